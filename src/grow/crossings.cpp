// Crossing triangles (crossings.hpp): the guard by the empty-ball argument over the triangles on
// each vertex, and triangles filed by the cell of their box's lower corner in levels of cells;
// the pair test is the exact one of common/triangle_intersection.hpp.
#include "grow/crossings.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "common/exact_predicates.hpp"
#include "common/separating_planes.hpp"
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

bool padded_circumball(const Vec3& a, const Vec3& b, const Vec3& c, Ball& out) {
  if (!circumball(a, b, c, out)) return false;
  const double radius2 = std::max({out.radius2, norm2(b - out.centre), norm2(c - out.centre)});
  const double size = std::abs(out.centre.x) + std::abs(out.centre.y) + std::abs(out.centre.z);
  const double reach = std::sqrt(radius2) * (1 + 1e-8) + 1e-8 * size;
  out.radius2 = reach * reach;
  return true;
}

CrossingPositions::CrossingPositions(const HashGrid& grid, std::span<const Vec3> exact,
                                     const Vec3& origin)
    : grid_(grid), exact_(exact), origin_(origin) {
  // Rounding to float moves a coordinate by at most 2^-24 of it: a point by 2^-24 of its norm.
  double farthest = 0;
  for (std::uint32_t k = 0; k < exact.size(); ++k)
    farthest = std::max(farthest, norm(grid.position(k)));
  rounding_ = std::ldexp(farthest, -23);
}

std::vector<Vec3> output_positions(const HashGrid& grid, std::span<const double> xyz,
                                   bool floats_exact) {
  std::vector<Vec3> out;
  if (floats_exact) return out;
  out.reserve(grid.size());
  for (std::uint32_t k = 0; k < grid.size(); ++k) {
    const double* p = &xyz[3 * std::size_t{grid.source(k)}];
    out.push_back({p[0], p[1], p[2]});
  }
  return out;
}

SeparatingPlanes CrossingPositions::exact_planes(const Triangle& t) const {
  return SeparatingPlanes(t, [&](Index v) { return exact_[v]; });
}

bool CrossingPositions::exact_separate(const SeparatingPlanes& planes,
                                       const Triangle& other) const {
  return planes.separate(other, [&](Index v) { return exact_[v]; });
}

bool CrossingPositions::exact_cross(const Triangle& a, const Triangle& b) const {
  if (a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) return false;
  const Vec3 ta[3] = {exact_[a[0]], exact_[a[1]], exact_[a[2]]};
  const Vec3 tb[3] = {exact_[b[0]], exact_[b[1]], exact_[b[2]]};
  return g2s::triangles_cross(ta, tb);
}

bool CrossingPositions::degenerate(const Triangle& t) const {
  if (exact_.empty()) return detail::degenerate(grid_.points(), t);
  double p[3][3];
  for (int k = 0; k < 3; ++k) {
    const Vec3& v = exact_[t[k]];
    p[k][0] = v.x, p[k][1] = v.y, p[k][2] = v.z;
  }
  return exact::collinear(p[0], p[1], p[2]);
}

bool CrossingPositions::exact_ball(const Triangle& t, Ball& out) const {
  // In the frame (the subtraction's rounding is far below the padding), widened by the most
  // any point's float lies from its position.
  if (!padded_circumball(exact_[t[0]] - origin_, exact_[t[1]] - origin_, exact_[t[2]] - origin_,
                         out)) {
    return false;
  }
  const double reach = std::sqrt(out.radius2) + rounding_;
  out.radius2 = reach * reach;
  return true;
}

namespace {
using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

// The pairs each thread found (every pair by one thread, once), sorted.
Pairs sorted_union(tbb::enumerable_thread_specific<Pairs>& found) {
  Pairs pairs;
  for (const Pairs& part : found) pairs.insert(pairs.end(), part.begin(), part.end());
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}
}  // namespace

CrossingGuard::CrossingGuard(const HashGrid& grid, const CrossingPositions& positions)
    : grid_(grid),
      positions_(positions),
      star_head_(grid.size(), kNoIndex),
      held_head_(grid.size(), kNoIndex) {}

bool CrossingGuard::gather(const Triangle& tri) {
  gathered_ = tri;
  in_ball_.clear();
  Ball ball;
  if (!positions_.ball(tri, ball)) return false;
  grid_.for_each_in_ball(ball.centre, std::sqrt(ball.radius2), [&](std::uint32_t j, double) {
    if (j != tri[0] && j != tri[1] && j != tri[2]) in_ball_.push_back(j);
  });
  return true;
}

bool CrossingGuard::crosses(const Triangle& tri, std::span<const Triangle> made) {
  if (!gather(tri)) return true;
  std::optional<SeparatingPlanes> planes;
  const auto crosses_one = [&](std::uint32_t other) {
    if (!planes) planes.emplace(positions_.planes(tri));
    return !positions_.separate(*planes, made[other]) && positions_.cross(tri, made[other]);
  };
  for (const Index v : in_ball_) {
    for (std::uint32_t at = star_head_[v]; at != kNoIndex; at = star_next_[at]) {
      if (crosses_one(at / 3)) return true;
    }
  }
  for (const Index v : tri) {
    for (std::uint32_t at = held_head_[v]; at != kNoIndex; at = held_[at].next) {
      if (crosses_one(held_[at].triangle)) return true;
    }
  }
  return false;
}

void CrossingGuard::file(std::uint32_t t, std::span<const Triangle> made) {
  const Triangle& tri = made[t];
  if (tri != gathered_) gather(tri);
  star_next_.resize(3 * std::size_t{t} + 3, kNoIndex);
  for (int k = 0; k < 3; ++k) {
    star_next_[3 * std::size_t{t} + k] = star_head_[tri[k]];
    star_head_[tri[k]] = 3 * t + static_cast<std::uint32_t>(k);
  }
  for (const Index v : in_ball_) {
    held_.push_back({t, held_head_[v]});
    held_head_[v] = static_cast<std::uint32_t>(held_.size() - 1);
  }
}

Pairs TriangleCells::crossing_pairs(const CrossingPositions& positions) const {
  std::vector<std::uint8_t> collinear(triangles_.size());  // degenerate triangles cross none
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles_.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t t = range.begin(); t < range.end(); ++t) {
                        collinear[t] = positions.degenerate(triangles_[t]);
                      }
                    });
  const Level& first = levels_[0];
  tbb::enumerable_thread_specific<Pairs> found;
  // The first level: each cell against itself and its 13 neighbours on the forward side, so
  // that every pair of cells is met once. Boxes are read in filing order (first.boxes), so the
  // pairs of two cells are tested from two short runs of memory.
  const auto cell_pairs = [&](std::size_t slot, Pairs& pairs) {
    const auto test = [&](std::uint32_t i, std::uint32_t j) {
      if (!overlap(first.boxes[i], first.boxes[j])) return;
      const std::uint32_t s = first.filed[i], t = first.filed[j];
      if (collinear[s] || collinear[t]) return;
      if (positions.cross(triangles_[s], triangles_[t])) {
        pairs.push_back({std::min(s, t), std::max(s, t)});
      }
    };
    const std::uint64_t k = first.keys[slot];
    for (std::uint32_t i = first.begin[slot]; i < first.end[slot]; ++i) {
      for (std::uint32_t j = i + 1; j < first.end[slot]; ++j) test(i, j);
    }
    const auto x = static_cast<std::int64_t>(k >> 42) - kBias;
    const auto y = static_cast<std::int64_t>(k >> 21 & 0x1FFFFF) - kBias;
    const auto z = static_cast<std::int64_t>(k & 0x1FFFFF) - kBias;
    for (int d = 14; d < 27; ++d) {  // offsets (dx, dy, dz) after (0, 0, 0) in z-y-x order
      const std::size_t other = first.find(key(x + d % 3 - 1, y + d / 3 % 3 - 1, z + d / 9 - 1));
      if (other == first.keys.size()) continue;
      for (std::uint32_t i = first.begin[slot]; i < first.end[slot]; ++i) {
        for (std::uint32_t j = first.begin[other]; j < first.end[other]; ++j) test(i, j);
      }
    }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, first.keys.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      Pairs& pairs = found.local();
                      for (std::size_t slot = range.begin(); slot < range.end(); ++slot) {
                        if (first.keys[slot] != kEmpty) cell_pairs(slot, pairs);
                      }
                    });
  // Triangles of the larger levels against everything near them (each pair of two such once).
  Pairs& pairs = found.local();
  const auto against_all = [&](std::uint32_t t, const Box& box) {
    for_each_near(box.lo, box.hi, [&](std::uint32_t other, const Box&) {
      if (other == t || (level_[other] != 0 && other < t)) return;
      if (collinear[t] || collinear[other]) return;
      if (positions.cross(triangles_[t], triangles_[other])) {
        pairs.push_back({std::min(t, other), std::max(t, other)});
      }
    });
  };
  for (std::size_t l = 1; l < levels_.size(); ++l) {
    const Level& level = levels_[l];
    for (std::size_t e = 0; e < level.filed.size(); ++e)
      against_all(level.filed[e], level.boxes[e]);
  }
  return sorted_union(found);
}

void TriangleCells::build(Level& level, std::span<const std::uint32_t> members,
                          std::span<const Box> boxes) {
  const auto home = [&](std::uint64_t k) {
    return static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> level.shift);
  };
  // Each member's cell key, worked out once. Both passes below look the keys up in the table,
  // whose slots are scattered over memory (megabytes on a large tile): the slot of the member
  // kAhead places on is loaded while this one is placed.
  constexpr std::size_t kAhead = 16;
  std::vector<std::uint64_t> member_keys(members.size());
  for (std::size_t i = 0; i < members.size(); ++i) {
    const Box& box = boxes[members[i]];
    member_keys[i] = key(level.coord(box.lo.x), level.coord(box.lo.y), level.coord(box.lo.z));
  }
  const auto load_ahead = [&](std::size_t i) {
    if (i + kAhead >= members.size()) return;
    const std::size_t s = home(member_keys[i + kAhead]);
    __builtin_prefetch(&level.keys[s]);
    __builtin_prefetch(&level.end[s]);
  };
  // The cells and their counts, the table doubled whenever it would be more than half full.
  std::size_t cells = 0;
  level.shift = 60;
  level.keys.assign(16, kEmpty);
  level.end.assign(16, 0);
  const auto slot_for = [&](std::uint64_t k) {
    std::size_t s = home(k);
    while (level.keys[s] != kEmpty && level.keys[s] != k) s = (s + 1) & (level.keys.size() - 1);
    return s;
  };
  for (std::size_t i = 0; i < members.size(); ++i) {
    load_ahead(i);
    const std::uint64_t k = member_keys[i];
    std::size_t s = slot_for(k);
    if (level.keys[s] == kEmpty) {
      if (2 * (cells + 1) > level.keys.size()) {
        std::vector<std::uint64_t> keys(2 * level.keys.size(), kEmpty);
        std::vector<std::uint32_t> counts(keys.size(), 0);
        keys.swap(level.keys);
        counts.swap(level.end);
        --level.shift;
        for (std::size_t old = 0; old < keys.size(); ++old) {
          if (keys[old] == kEmpty) continue;
          const std::size_t moved = slot_for(keys[old]);
          level.keys[moved] = keys[old];
          level.end[moved] = counts[old];
        }
        s = slot_for(k);
      }
      level.keys[s] = k;
      ++cells;
    }
    ++level.end[s];
  }
  // Counting sort by slot: offsets, then place.
  const std::size_t slots = level.keys.size();
  level.begin.assign(slots + 1, 0);
  std::uint32_t offset = 0;
  for (std::size_t s = 0; s < slots; ++s) {
    level.begin[s] = offset;
    offset += level.end[s];
    level.end[s] = level.begin[s];
  }
  level.begin[slots] = offset;
  level.filed.resize(members.size());
  level.boxes.resize(members.size());
  for (std::size_t i = 0; i < members.size(); ++i) {
    load_ahead(i);
    const std::uint32_t t = members[i];
    const std::uint32_t at = level.end[level.find(member_keys[i])]++;
    level.filed[at] = t;
    level.boxes[at] = boxes[t];
  }
}

TriangleCells::TriangleCells(std::span<const Vec3f> points, std::span<const Triangle> triangles)
    : points_(points), triangles_(triangles), level_(triangles.size(), 0) {
  // Each box worked out once: its corners are scattered over the points.
  std::vector<Box> boxes(triangles.size());
  std::vector<float> extents(triangles.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    const Box& box = boxes[t] = box_of(points, triangles[t]);
    extents[t] = std::max({box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z});
  }
  // The first level's cell holds nine triangles in ten whole; the rest are few enough to be
  // looked up from their own, larger cells.
  double cell = 1;
  float largest = 0;
  if (!triangles.empty()) {
    std::vector<float> sorted = extents;
    const auto at = sorted.begin() + static_cast<long>(sorted.size() * 9 / 10);
    std::nth_element(sorted.begin(), at, sorted.end());
    cell = std::max(1.05 * *at, 1e-30);
    largest = *std::max_element(extents.begin(), extents.end());
  }
  constexpr double kGrowth = 8;  // a level's cell edge, in the previous level's
  levels_.emplace_back().inverse_cell = 1.0 / cell;
  for (double edge = cell; largest > 0.99 * edge; edge *= kGrowth) {
    levels_.emplace_back().inverse_cell = 1.0 / (kGrowth * edge);
  }
  std::vector<std::vector<std::uint32_t>> members(levels_.size());
  members[0].reserve(triangles.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    std::size_t l = 0;
    while (l + 1 < levels_.size() && extents[t] > 0.99 / levels_[l].inverse_cell) ++l;
    level_[t] = static_cast<std::uint8_t>(l);
    members[l].push_back(t);
  }
  extents = {};
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    build(levels_[l], members[l], boxes);
    members[l] = {};
  }
}

}  // namespace g2s::detail
