// Crossing triangles (crossings.hpp): triangles hashed into cells by their bounding boxes, pairs
// tested only within a cell and only in the one cell where their boxes' overlap begins, so each
// pair is tested once; the test itself reduces to signs of orientation determinants.
#include "grow/crossings.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace g2s::detail {
namespace {

// Sign of the volume of (b - a, c - a, d - a): positive when d lies on the side of plane abc
// that its normal (b - a) x (c - a) points to.
int orient3d(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& d) {
  const double adx = double{a.x} - d.x, ady = double{a.y} - d.y, adz = double{a.z} - d.z;
  const double bdx = double{b.x} - d.x, bdy = double{b.y} - d.y, bdz = double{b.z} - d.z;
  const double cdx = double{c.x} - d.x, cdy = double{c.y} - d.y, cdz = double{c.z} - d.z;
  const double det =
      adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) + cdx * (ady * bdz - adz * bdy);
  return (det < 0) - (det > 0);
}

// 2D orientation in the plane that drops axis `drop`.
int orient2d(const Vec3f& a, const Vec3f& b, const Vec3f& c, int drop) {
  const auto u = [drop](const Vec3f& p) { return drop == 0 ? double{p.y} : double{p.x}; };
  const auto v = [drop](const Vec3f& p) { return drop == 2 ? double{p.y} : double{p.z}; };
  const double det = (u(b) - u(a)) * (v(c) - v(a)) - (v(b) - v(a)) * (u(c) - u(a));
  return (det > 0) - (det < 0);
}

// Closed segment pq against closed triangle abc, all in one plane (projected along `drop`).
bool coplanar_segment_hits_triangle(const Vec3f& p, const Vec3f& q, const Vec3f& a, const Vec3f& b,
                                    const Vec3f& c, int drop) {
  const int abc = orient2d(a, b, c, drop);
  if (abc == 0) return false;  // degenerate triangle
  const auto inside = [&](const Vec3f& x) {
    return orient2d(a, b, x, drop) * abc >= 0 && orient2d(b, c, x, drop) * abc >= 0 &&
           orient2d(c, a, x, drop) * abc >= 0;
  };
  if (inside(p) || inside(q)) return true;
  const Vec3f* corners[3] = {&a, &b, &c};
  for (int k = 0; k < 3; ++k) {
    const Vec3f& u = *corners[k];
    const Vec3f& v = *corners[(k + 1) % 3];
    const int s1 = orient2d(p, q, u, drop), s2 = orient2d(p, q, v, drop);
    const int s3 = orient2d(u, v, p, drop), s4 = orient2d(u, v, q, drop);
    if (s1 * s2 <= 0 && s3 * s4 <= 0) {
      if (s1 == 0 && s2 == 0) {  // collinear: overlap of the projections on the line
        const auto lo_hi = [drop](const Vec3f& x, const Vec3f& y) {
          const double xs = drop == 0 ? x.y : x.x, ys = drop == 0 ? y.y : y.x;
          const double xt = drop == 2 ? x.y : x.z, yt = drop == 2 ? y.y : y.z;
          return std::array<double, 4>{std::min(xs, ys), std::max(xs, ys), std::min(xt, yt),
                                       std::max(xt, yt)};
        };
        const auto r1 = lo_hi(p, q), r2 = lo_hi(u, v);
        if (r1[0] <= r2[1] && r2[0] <= r1[1] && r1[2] <= r2[3] && r2[2] <= r1[3]) return true;
        continue;
      }
      return true;
    }
  }
  return false;
}

int dominant_axis(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3 n = cross(Vec3(b) - Vec3(a), Vec3(c) - Vec3(a));
  const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
  return ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
}

// Closed segment pq against closed triangle abc.
bool segment_hits_triangle(const Vec3f& p, const Vec3f& q, const Vec3f& a, const Vec3f& b,
                           const Vec3f& c) {
  const int sp = orient3d(a, b, c, p), sq = orient3d(a, b, c, q);
  if (sp * sq > 0) return false;
  if (sp == 0 && sq == 0) {
    return coplanar_segment_hits_triangle(p, q, a, b, c, dominant_axis(a, b, c));
  }
  // The line pq crosses the plane between p and q: inside when it passes every edge on one side.
  const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

bool degenerate(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3 n = cross(Vec3(b) - Vec3(a), Vec3(c) - Vec3(a));
  return n.x == 0 && n.y == 0 && n.z == 0;
}

}  // namespace

bool triangles_cross(std::span<const Vec3f> points, const Triangle& ta, const Triangle& tb) {
  int shared = 0;
  int in_a[3] = {-1, -1, -1};  // per corner of a: the corner of b it equals, or -1
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (ta[i] == tb[j]) {
        in_a[i] = j;
        ++shared;
      }
    }
  }
  if (shared == 3) return false;
  const Vec3f a[3] = {points[ta[0]], points[ta[1]], points[ta[2]]};
  const Vec3f b[3] = {points[tb[0]], points[tb[1]], points[tb[2]]};
  if (degenerate(a[0], a[1], a[2]) || degenerate(b[0], b[1], b[2])) return false;
  if (shared == 2) {
    // Only coplanar triangles folded onto each other (apexes on one side of the edge) overlap.
    int i = 0;
    while (in_a[i] >= 0) ++i;
    int j = 0;
    while (j == in_a[(i + 1) % 3] || j == in_a[(i + 2) % 3]) ++j;
    const Vec3f& u = a[(i + 1) % 3];
    const Vec3f& v = a[(i + 2) % 3];
    if (orient3d(u, v, a[i], b[j]) != 0) return false;
    const int drop = dominant_axis(a[0], a[1], a[2]);
    return orient2d(u, v, a[i], drop) == orient2d(u, v, b[j], drop);
  }
  if (shared == 1) {
    // Triangles wab and wcd meet beyond w exactly when ab meets wcd or cd meets wab.
    int i = 0;
    while (in_a[i] < 0) ++i;
    const int j = in_a[i];
    return segment_hits_triangle(a[(i + 1) % 3], a[(i + 2) % 3], b[0], b[1], b[2]) ||
           segment_hits_triangle(b[(j + 1) % 3], b[(j + 2) % 3], a[0], a[1], a[2]);
  }
  // No shared corner: any common point means a crossing. Quick exit when one lies wholly on
  // one side of the other's plane.
  const int sa0 = orient3d(b[0], b[1], b[2], a[0]), sa1 = orient3d(b[0], b[1], b[2], a[1]),
            sa2 = orient3d(b[0], b[1], b[2], a[2]);
  if (sa0 == sa1 && sa1 == sa2 && sa0 != 0) return false;
  const int sb0 = orient3d(a[0], a[1], a[2], b[0]), sb1 = orient3d(a[0], a[1], a[2], b[1]),
            sb2 = orient3d(a[0], a[1], a[2], b[2]);
  if (sb0 == sb1 && sb1 == sb2 && sb0 != 0) return false;
  // Two triangles intersect exactly when an edge of one meets the other.
  for (int k = 0; k < 3; ++k) {
    if (segment_hits_triangle(a[k], a[(k + 1) % 3], b[0], b[1], b[2])) return true;
    if (segment_hits_triangle(b[k], b[(k + 1) % 3], a[0], a[1], a[2])) return true;
  }
  return false;
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
    : points_(points), triangles_(triangles), boxes_(triangles.size()), size_(triangles.size(), 0) {
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
