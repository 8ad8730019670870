// Crossing triangles: pairs that meet other than in a shared corner or a shared edge. The grower
// makes no triangle that crosses one made before (CrossingGuard), and checks the triangles it
// fills holes with against the rest (TriangleCells), both judged on the coordinates the output
// holds (CrossingPositions), so that no mesh it writes crosses itself (docs/algorithm.md, "No
// crossing triangles").
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "common/separating_planes.hpp"
#include "common/vec3.hpp"
#include "g2s/types.hpp"
#include "grid/hash_grid.hpp"

namespace g2s::detail {

// True when the triangle's corners lie on one line (exactly).
bool degenerate(std::span<const Vec3f> points, const Triangle& t);

// The ball through a, b and c centred in their plane, its radius padded by 1e-8 of itself and of
// the centre's coordinates (far beyond the rounding of the centre): a point outside it is
// outside the exact ball. False for (nearly) collinear corners.
bool padded_circumball(const Vec3& a, const Vec3& b, const Vec3& c, Ball& out);

// True when the closed triangles a and b (corner indices into points, which hold no two equal
// positions; neither degenerate) intersect other than in corners or an edge they share; exact
// (common/triangle_intersection.hpp). The same triangle twice never crosses.
bool triangles_cross(std::span<const Vec3f> points, const Triangle& a, const Triangle& b);

// The positions the crossing tests decide on: the ones the output holds (the input's double
// coordinates), so that a mesh the tests pass has no crossing once written. Where the grid's
// floats are exactly those less the frame's origin (a cloud read as float: LocalFrame), the
// floats are tested; otherwise (coordinates finer than float, as in a double PLY or a LAS file)
// the output's positions are, and balls are widened by float's rounding, so that the grid's
// float searches still find every point a ball of the output's positions holds. Boxes stay
// float: rounding keeps order, so boxes that overlap in the output's positions overlap in float.
class CrossingPositions {
 public:
  // Inputs: the grid; exact, per grid point its position in the output (empty: the floats are
  // exact); origin, the grid frame's origin in those positions (grid.point(k) is exact[k] -
  // origin rounded to float). The spans must outlive the object.
  explicit CrossingPositions(const HashGrid& grid, std::span<const Vec3> exact = {},
                             const Vec3& origin = {});

  // Separating planes of t (common/separating_planes.hpp), and whether they separate `other`.
  // The float case inline: these run for every pair a crossing test meets.
  SeparatingPlanes planes(const Triangle& t) const {
    return exact_.empty() ? SeparatingPlanes(grid_.points(), t) : exact_planes(t);
  }
  bool separate(const SeparatingPlanes& planes, const Triangle& other) const {
    return exact_.empty() ? planes.separate(grid_.points(), other) : exact_separate(planes, other);
  }
  // Whether the triangles cross (triangles_cross, on these positions).
  bool cross(const Triangle& a, const Triangle& b) const {
    return exact_.empty() ? triangles_cross(grid_.points(), a, b) : exact_cross(a, b);
  }
  // Whether t's corners lie on one line (exactly).
  bool degenerate(const Triangle& t) const;
  // A ball in the grid's float frame that holds every point whose position lies in t's padded
  // circumball (padded_circumball, on these positions); false for a sliver.
  bool ball(const Triangle& t, Ball& out) const {
    return exact_.empty() ? padded_circumball(grid_.position(t[0]), grid_.position(t[1]),
                                              grid_.position(t[2]), out)
                          : exact_ball(t, out);
  }

 private:
  SeparatingPlanes exact_planes(const Triangle& t) const;
  bool exact_separate(const SeparatingPlanes& planes, const Triangle& other) const;
  bool exact_cross(const Triangle& a, const Triangle& b) const;
  bool exact_ball(const Triangle& t, Ball& out) const;

  const HashGrid& grid_;
  std::span<const Vec3> exact_;
  Vec3 origin_;
  double rounding_ = 0;  // how far a float point may lie from its exact position, at most
};

// The positions GrowContext::exact_positions asks for: per grid point its coordinates in xyz (3
// doubles per point the grid was built from, in that order), or none when floats_exact (the
// grid's floats are those coordinates less the frame's origin, LocalFrame::exact).
std::vector<Vec3> output_positions(const HashGrid& grid, std::span<const double> xyz,
                                   bool floats_exact);

// An axis-aligned box: two triangles whose boxes do not overlap cannot cross.
struct Box {
  Vec3f lo, hi;
};
inline bool overlap(const Box& a, const Box& b) {
  return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
         a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}
// The box of a point set grown to hold p.
inline Box enclose(const Box& box, const Vec3f& p) {
  return {{std::min(box.lo.x, p.x), std::min(box.lo.y, p.y), std::min(box.lo.z, p.z)},
          {std::max(box.hi.x, p.x), std::max(box.hi.y, p.y), std::max(box.hi.z, p.z)}};
}
// The box of triangle t's corners.
inline Box box_of(std::span<const Vec3f> points, const Triangle& t) {
  const Box corner{points[t[0]], points[t[0]]};
  return enclose(enclose(corner, points[t[1]]), points[t[2]]);
}

// Triangles made one at a time, none crossing another (triangles_cross): the grower asks about
// each triangle before making it. By this fact: two triangles, each with the corners it does
// not share with the other outside the other's padded circumball (padded_circumball), never
// cross. The difference of a point's powers with respect to the two spheres is an affine
// function, positive at one triangle's other corners and negative at the other's, so the
// triangles can meet only where it vanishes, in the corners they share. So a new triangle needs
// testing only against the triangles on the vertices in its ball and those whose balls hold one
// of its corners; on a clean scan both lists are nearly always empty. Per point the guard keeps
// the triangles on it and the triangles whose balls hold it (lists threaded through flat arrays
// that grow with the triangles, no allocation of its own per triangle).
// Cost: one ball query per triangle asked about (file reuses the last), and the exact test only
// where the separating planes (common/separating_planes.hpp) do not settle a pair.
class CrossingGuard {
 public:
  // Inputs: the grid whose points the triangles' corners index, and the positions the tests
  // decide on. Both must outlive the guard.
  CrossingGuard(const HashGrid& grid, const CrossingPositions& positions);
  // Inputs: a triangle with a circumball (not filed), and `made`, the triangles filed so far by
  // their indices. Output: whether it crosses a filed triangle (true also for a sliver without
  // a circumball, which the grower never makes).
  bool crosses(const Triangle& tri, std::span<const Triangle> made);
  // Files made[t], a triangle made without crossing a filed one (or one kept whatever crosses
  // it, such as a seam's preload; crosses() need not have been asked).
  void file(std::uint32_t t, std::span<const Triangle> made);

 private:
  // The points other than its corners in tri's padded circumball, into in_ball_ (none for a
  // sliver); false for a sliver.
  bool gather(const Triangle& tri);
  struct Held {
    std::uint32_t triangle, next;
  };
  const HashGrid& grid_;
  const CrossingPositions& positions_;
  std::vector<std::uint32_t> star_head_;  // per point: its last corner slot 3t+k, or kNoIndex
  std::vector<std::uint32_t> star_next_;  // per corner slot: the point's corner filed before
  std::vector<std::uint32_t> held_head_;  // per point: its last entry in held_, or kNoIndex
  std::vector<Held> held_;
  std::vector<Index> in_ball_;
  Triangle gathered_{kNoIndex, kNoIndex, kNoIndex};  // the triangle in_ball_ is of
};

// Triangles filed by the cell of their bounding box's lower corner, in levels of cells each 8
// times larger than the one before: a triangle is filed in the first level whose cell its box
// fits (the first level holds nine in ten). Two triangles whose boxes overlap are then filed in the
// same or neighbouring cells of their levels, so a query reads a few cells per level, and a
// build is one counting pass per level.
// Inputs: points (the triangles' corners index them), triangles. The spans must outlive the
// object.
class TriangleCells {
 public:
  TriangleCells(std::span<const Vec3f> points, std::span<const Triangle> triangles);

  // Calls visit(t, box of t) once for every triangle whose bounding box overlaps the box
  // [lo, hi].
  template <class Visit>
  void for_each_near(const Vec3f& lo, const Vec3f& hi, Visit&& visit) const;

  // Every pair (s, t), s < t, of non-degenerate triangles that cross, judged on `positions`
  // (of the same points). Sorted.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> crossing_pairs(
      const CrossingPositions& positions) const;

 private:
  // One size of cell: per filed triangle, in cell order; cells in an open-addressing table at
  // most half full (sized by the cells, far fewer than the triangles).
  struct Level {
    double inverse_cell = 1;
    std::vector<std::uint64_t> keys;  // per slot: cell key, or kEmpty
    std::vector<std::uint32_t> begin, end;
    std::vector<std::uint32_t> filed;  // triangle indices grouped by cell
    std::vector<Box> boxes;            // their boxes, in the same order
    int shift = 60;
    // The cell coordinate of v, clamped to the keys' range: floor, clamped first so that the
    // integer conversion does it (no call to floor; these run in every query).
    std::int64_t coord(float v) const {
      const double c = std::clamp(v * inverse_cell, double(-kBias), double(kBias - 1));
      const auto i = static_cast<std::int64_t>(c);
      return c < static_cast<double>(i) ? i - 1 : i;
    }
    std::size_t find(std::uint64_t k) const {  // slot, or keys.size()
      for (std::size_t s = (k * 0x9E3779B97F4A7C15ull) >> shift;; s = (s + 1) & (keys.size() - 1)) {
        if (keys[s] == k) return s;
        if (keys[s] == kEmpty) return keys.size();
      }
    }
  };
  static constexpr std::uint64_t kEmpty = ~0ull;
  static constexpr std::int64_t kBias = std::int64_t{1} << 20;  // added to cell coordinates
  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::uint64_t>(x + kBias) << 42 |
           static_cast<std::uint64_t>(y + kBias) << 21 | static_cast<std::uint64_t>(z + kBias);
  }
  // Files `members` in `level`; boxes[t] is triangle t's box.
  void build(Level& level, std::span<const std::uint32_t> members, std::span<const Box> boxes);
  // Calls visit(e) for the places e in level.filed of the triangles whose lower corner lies in
  // the cells that [lo - cell, hi] covers: every filed triangle whose box can overlap [lo, hi].
  template <class Visit>
  void scan(const Level& level, const Vec3f& lo, const Vec3f& hi, Visit&& visit) const;

  std::span<const Vec3f> points_;
  std::span<const Triangle> triangles_;
  std::vector<std::uint8_t> level_;  // per triangle: the level it is filed in
  std::vector<Level> levels_;
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
        for (std::uint32_t e = level.begin[s]; e < level.end[s]; ++e) visit(e);
      }
    }
  }
}

template <class Visit>
void TriangleCells::for_each_near(const Vec3f& lo, const Vec3f& hi, Visit&& visit) const {
  const Box query{lo, hi};
  for (const Level& level : levels_) {
    if (level.filed.empty()) continue;
    // The boxes in filing order: a cell's triangles are read from one run of memory.
    scan(level, lo, hi, [&](std::uint32_t e) {
      if (overlap(level.boxes[e], query)) visit(level.filed[e], level.boxes[e]);
    });
  }
}

}  // namespace g2s::detail
