// Crossing triangles among the triangles of one growth run: pairs that meet other than in a
// shared corner or a shared edge. The grower removes one triangle of each pair once growth is
// over, and checks the triangles it fills holes with, so that no mesh it makes crosses itself
// (docs/algorithm.md, "No crossing triangles").
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s::detail {

// True when the triangle's corners lie on one line (exactly).
bool degenerate(std::span<const Vec3f> points, const Triangle& t);

// True when the closed triangles a and b (corner indices into points, which hold no two equal
// positions; neither degenerate) intersect other than in corners or an edge they share; exact
// (common/triangle_intersection.hpp). The same triangle twice never crosses.
bool triangles_cross(std::span<const Vec3f> points, const Triangle& a, const Triangle& b);

// Triangles filed by the cell of their bounding box's lower corner, in two sizes of cell: a
// triangle whose box fits in the small cell (nearly all) is filed there, a larger one in the
// large cell, a larger one still in a list. Two triangles whose boxes overlap are then filed in
// the same or neighbouring cells, so a query reads a few cells, and a build is one counting pass.
// Inputs: points (the triangles' corners index them), triangles. The spans must outlive the
// object.
class TriangleCells {
 public:
  TriangleCells(std::span<const Vec3f> points, std::span<const Triangle> triangles);

  // Calls visit(t) once for every triangle whose bounding box overlaps the box [lo, hi].
  template <class Visit>
  void for_each_near(const Vec3f& lo, const Vec3f& hi, Visit&& visit) const;

  bool degenerate(std::uint32_t t) const { return degenerate_[t] != 0; }

  // Pairs (s, t), s < t, of non-degenerate triangles that cross (triangles_cross), where skip(s)
  // and skip(t) are false and focus(s) or focus(t) is true. Sorted.
  template <class Skip, class Focus>
  std::vector<std::pair<std::uint32_t, std::uint32_t>> crossing_pairs(Skip&& skip,
                                                                      Focus&& focus) const;

 private:
  struct Box {
    Vec3f lo, hi;
  };
  // One size of cell: per filed triangle, in cell order; cells in an open-addressing table.
  struct Level {
    double inverse_cell = 1;
    std::vector<std::uint64_t> keys;  // per slot: cell key, or kEmpty
    std::vector<std::uint32_t> begin, end;
    std::vector<std::uint32_t> filed;  // triangle indices grouped by cell
    std::vector<Box> boxes;            // their boxes, in the same order
    int shift = 60;
    std::int64_t coord(float v) const;
    std::size_t find(std::uint64_t key) const;  // slot, or keys.size()
  };
  static constexpr std::uint64_t kEmpty = ~0ull;
  static constexpr std::int64_t kBias = std::int64_t{1} << 20;  // added to cell coordinates
  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z);
  static bool overlap(const Box& a, const Box& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
           a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
  }
  void build(Level& level, std::span<const std::uint32_t> members);
  // Calls visit(t) for the triangles of `level` whose lower corner lies in the cells that
  // [lo - cell, hi] covers: every filed triangle whose box can overlap [lo, hi].
  template <class Visit>
  void scan(const Level& level, const Vec3f& lo, const Vec3f& hi, Visit&& visit) const;

  std::span<const Vec3f> points_;
  std::span<const Triangle> triangles_;
  std::vector<Box> boxes_;
  std::vector<std::uint8_t> size_;  // per triangle: 0 small, 1 large, 2 huge
  std::vector<std::uint8_t> degenerate_;
  Level small_, large_;
  std::vector<std::uint32_t> huge_;
};

template <class Visit>
void TriangleCells::scan(const Level& level, const Vec3f& lo, const Vec3f& hi,
                         Visit&& visit) const {
  const float reach = static_cast<float>(1.0 / level.inverse_cell);
  const std::int64_t x0 = level.coord(lo.x - reach), y0 = level.coord(lo.y - reach),
                     z0 = level.coord(lo.z - reach);
  const std::int64_t x1 = level.coord(hi.x), y1 = level.coord(hi.y), z1 = level.coord(hi.z);
  for (std::int64_t z = z0; z <= z1; ++z) {
    for (std::int64_t y = y0; y <= y1; ++y) {
      for (std::int64_t x = x0; x <= x1; ++x) {
        const std::size_t s = level.find(key(x, y, z));
        if (s == level.keys.size()) continue;
        for (std::uint32_t e = level.begin[s]; e < level.end[s]; ++e) visit(level.filed[e]);
      }
    }
  }
}

template <class Visit>
void TriangleCells::for_each_near(const Vec3f& lo, const Vec3f& hi, Visit&& visit) const {
  const Box query{lo, hi};
  const auto near = [&](std::uint32_t t) {
    if (overlap(boxes_[t], query)) visit(t);
  };
  scan(small_, lo, hi, near);
  scan(large_, lo, hi, near);
  for (const std::uint32_t t : huge_) near(t);
}

template <class Skip, class Focus>
std::vector<std::pair<std::uint32_t, std::uint32_t>> TriangleCells::crossing_pairs(
    Skip&& skip, Focus&& focus) const {
  using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;
  tbb::enumerable_thread_specific<Pairs> found;
  // Small triangles: each cell against itself and its 13 neighbours on the forward side, so
  // that every pair of cells is met once. Boxes are read in filing order (small_.boxes), so the
  // pairs of two cells are tested from two short runs of memory.
  const auto cell_pairs = [&](std::size_t slot, Pairs& pairs) {
    const auto test = [&](std::uint32_t i, std::uint32_t j) {
      if (!overlap(small_.boxes[i], small_.boxes[j])) return;
      const std::uint32_t s = small_.filed[i], t = small_.filed[j];
      if (degenerate_[s] || degenerate_[t] || skip(s) || skip(t) || !(focus(s) || focus(t))) return;
      if (triangles_cross(points_, triangles_[s], triangles_[t])) {
        pairs.push_back({std::min(s, t), std::max(s, t)});
      }
    };
    const std::uint64_t k = small_.keys[slot];
    for (std::uint32_t i = small_.begin[slot]; i < small_.end[slot]; ++i) {
      for (std::uint32_t j = i + 1; j < small_.end[slot]; ++j) test(i, j);
    }
    const auto x = static_cast<std::int64_t>(k >> 42) - kBias;
    const auto y = static_cast<std::int64_t>(k >> 21 & 0x1FFFFF) - kBias;
    const auto z = static_cast<std::int64_t>(k & 0x1FFFFF) - kBias;
    for (int d = 14; d < 27; ++d) {  // offsets (dx, dy, dz) after (0, 0, 0) in z-y-x order
      const std::size_t other = small_.find(key(x + d % 3 - 1, y + d / 3 % 3 - 1, z + d / 9 - 1));
      if (other == small_.keys.size()) continue;
      for (std::uint32_t i = small_.begin[slot]; i < small_.end[slot]; ++i) {
        for (std::uint32_t j = small_.begin[other]; j < small_.end[other]; ++j) test(i, j);
      }
    }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, small_.keys.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      Pairs& pairs = found.local();
                      for (std::size_t slot = range.begin(); slot < range.end(); ++slot) {
                        if (small_.keys[slot] != kEmpty) cell_pairs(slot, pairs);
                      }
                    });
  Pairs pairs;
  for (const Pairs& part : found) pairs.insert(pairs.end(), part.begin(), part.end());
  // Larger triangles against everything near them (each pair of two larger ones once).
  const auto against_all = [&](std::uint32_t t) {
    for_each_near(boxes_[t].lo, boxes_[t].hi, [&](std::uint32_t other) {
      if (other == t || (size_[other] != 0 && other < t)) return;
      if (degenerate_[t] || degenerate_[other] || skip(t) || skip(other) ||
          !(focus(t) || focus(other))) {
        return;
      }
      if (triangles_cross(points_, triangles_[t], triangles_[other])) {
        pairs.push_back({std::min(t, other), std::max(t, other)});
      }
    });
  };
  for (const std::uint32_t t : large_.filed) against_all(t);
  for (const std::uint32_t t : huge_) against_all(t);
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace g2s::detail
