// Crossing triangles (crossings.hpp): triangles filed by the cell of their box's lower corner, in
// two sizes of cell; the pair test is the exact one of common/triangle_intersection.hpp.
#include "grow/crossings.hpp"

#include <algorithm>
#include <cmath>

#include "common/exact_predicates.hpp"
#include "common/triangle_intersection.hpp"

namespace g2s::detail {
bool degenerate(std::span<const Vec3f> points, const Triangle& t) {
  double p[3][3];
  for (int k = 0; k < 3; ++k)
    p[k][0] = points[t[k]].x, p[k][1] = points[t[k]].y, p[k][2] = points[t[k]].z;
  return exact::collinear(p[0], p[1], p[2]);
}

bool triangles_cross(std::span<const Vec3f> points, const Triangle& a, const Triangle& b) {
  if (a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) return false;
  // The exact test takes corners with equal coordinates as shared: in a grid, equal coordinates
  // are one point (exact duplicates are merged), so sharing is by index as well.
  const Vec3f ta[3] = {points[a[0]], points[a[1]], points[a[2]]};
  const Vec3f tb[3] = {points[b[0]], points[b[1]], points[b[2]]};
  return g2s::triangles_cross(ta, tb);
}

std::int64_t TriangleCells::Level::coord(float v) const {
  const double c = std::floor(v * inverse_cell);
  return static_cast<std::int64_t>(std::clamp(c, double(-kBias), double(kBias - 1)));
}

std::uint64_t TriangleCells::key(std::int64_t x, std::int64_t y, std::int64_t z) {
  return static_cast<std::uint64_t>(x + kBias) << 42 | static_cast<std::uint64_t>(y + kBias) << 21 |
         static_cast<std::uint64_t>(z + kBias);
}

std::size_t TriangleCells::Level::find(std::uint64_t k) const {
  for (std::size_t s = (k * 0x9E3779B97F4A7C15ull) >> shift;; s = (s + 1) & (keys.size() - 1)) {
    if (keys[s] == k) return s;
    if (keys[s] == kEmpty) return keys.size();
  }
}

void TriangleCells::build(Level& level, std::span<const std::uint32_t> members) {
  std::size_t slots = 16;
  level.shift = 60;
  while (slots < 2 * members.size()) slots *= 2, --level.shift;
  level.keys.assign(slots, kEmpty);
  level.begin.assign(slots + 1, 0);
  level.end.assign(slots, 0);
  // Counting sort by slot: count, offsets, then place.
  std::vector<std::uint32_t> slot_of(members.size());
  for (std::size_t m = 0; m < members.size(); ++m) {
    const Vec3f& lo = boxes_[members[m]].lo;
    const std::uint64_t k = key(level.coord(lo.x), level.coord(lo.y), level.coord(lo.z));
    std::size_t s = (k * 0x9E3779B97F4A7C15ull) >> level.shift;
    while (level.keys[s] != kEmpty && level.keys[s] != k) s = (s + 1) & (slots - 1);
    level.keys[s] = k;
    slot_of[m] = static_cast<std::uint32_t>(s);
    ++level.end[s];
  }
  std::uint32_t offset = 0;
  for (std::size_t s = 0; s < slots; ++s) {
    level.begin[s] = offset;
    offset += level.end[s];
    level.end[s] = level.begin[s];
  }
  level.filed.resize(members.size());
  level.boxes.resize(members.size());
  for (std::size_t m = 0; m < members.size(); ++m) {
    const std::uint32_t at = level.end[slot_of[m]]++;
    level.filed[at] = members[m];
    level.boxes[at] = boxes_[members[m]];
  }
}

TriangleCells::TriangleCells(std::span<const Vec3f> points, std::span<const Triangle> triangles)
    : points_(points),
      triangles_(triangles),
      boxes_(triangles.size()),
      size_(triangles.size(), 0),
      degenerate_(triangles.size(), 0) {
  std::vector<float> extents(triangles.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    const Vec3f &p0 = points[tri[0]], &p1 = points[tri[1]], &p2 = points[tri[2]];
    Box& box = boxes_[t];
    box.lo = {std::min({p0.x, p1.x, p2.x}), std::min({p0.y, p1.y, p2.y}),
              std::min({p0.z, p1.z, p2.z})};
    box.hi = {std::max({p0.x, p1.x, p2.x}), std::max({p0.y, p1.y, p2.y}),
              std::max({p0.z, p1.z, p2.z})};
    extents[t] = std::max({box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z});
    degenerate_[t] = detail::degenerate(points, tri);
  }
  // The small cell holds nine triangles in ten whole: the rest are few enough to be looked up
  // from their own, larger cells.
  double cell = 1;
  if (!triangles.empty()) {
    std::vector<float> sorted = extents;
    const auto at = sorted.begin() + static_cast<long>(sorted.size() * 9 / 10);
    std::nth_element(sorted.begin(), at, sorted.end());
    cell = std::max(1.05 * *at, 1e-30);
  }
  constexpr double kLargeCells = 8;  // the large cell's edge, in small cells
  small_.inverse_cell = 1.0 / cell;
  large_.inverse_cell = 1.0 / (kLargeCells * cell);
  std::vector<std::uint32_t> small, large;
  small.reserve(triangles.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    if (extents[t] <= 0.99 * cell) {
      small.push_back(t);
    } else if (extents[t] <= 0.99 * kLargeCells * cell) {
      large.push_back(t);
      size_[t] = 1;
    } else {
      huge_.push_back(t);
      size_[t] = 2;
    }
  }
  build(small_, small);
  build(large_, large);
}

}  // namespace g2s::detail
