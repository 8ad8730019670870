// The grower's gap closing (src/grow/grower.cpp, close_three_edge_gaps) on a hand-made front:
// three kept triangles around a triangular gap, with a context point in the gap that is every
// gap edge's Gabriel point but may not join, so the front itself leaves the gap open. And the
// removal of scraps (remove_scraps): a lone triangle near a flat patch, and one far from it,
// grown or loaded before the run. And
// the cap that closes a piece's only loop with a point left over (cap_single_loops). And hole
// filling over points a run may fill but not grow from (a seam's live context).
#include "grow/grower.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "grid/hash_grid.hpp"

namespace {

using g2s::Index;
using g2s::Triangle;

struct GapRun {
  std::vector<Triangle> grown;  // in input indices
  std::vector<std::uint8_t> flip;
};

// Points: the gap A B X (0-2), the outer corners of its three neighbours (3-5), the context
// point D just above the gap's centre (6).
GapRun grow_around_gap(bool close_gaps) {
  // clang-format off
  const std::vector<float> xyz{
      0,     0,       0,       // A
      1,     0,       0,       // B
      0.5f,  0.866f,  0,       // X
      0.5f,  -0.866f, 0,       // beyond A-B
      1.5f,  0.866f,  0,       // beyond B-X
      -0.5f, 0.866f,  0,       // beyond X-A
      0.5f,  0.2887f, 0.05f};  // D
  // clang-format on
  const std::vector<Index> ids{0, 1, 2, 3, 4, 5, 6};
  const g2s::HashGrid grid(xyz, ids);
  std::array<Index, 7> at{};  // input index -> grid index
  for (std::uint32_t k = 0; k < grid.size(); ++k) at[grid.id(k)] = k;
  // Each neighbour faces +z and traverses its gap edge against the gap's A->B->X.
  const std::vector<Triangle> preload{
      {at[1], at[0], at[3]}, {at[2], at[1], at[4]}, {at[0], at[2], at[5]}};
  const std::vector<std::uint32_t> labels{0, 0, 0};
  std::vector<std::uint8_t> growable(grid.size(), 0);
  for (Index v : {0, 1, 2}) growable[at[v]] = 1;  // the outer corners and D are context
  g2s::MeshOptions options;
  options.close_gaps = close_gaps;
  if (!close_gaps) options.max_hole_edges = 0;  // hole filling would close the gap as well
  g2s::GrowResult r = g2s::grow_mesh(grid, options, {preload, labels, growable, {}, 0, {}});
  GapRun run;
  for (const Triangle& t : r.triangles) {
    run.grown.push_back({grid.id(t[0]), grid.id(t[1]), grid.id(t[2])});
  }
  run.flip.assign(r.flip.begin() + static_cast<long>(preload.size()), r.flip.end());
  return run;
}

// The same cyclic order as a -> b -> c.
bool same_cycle(const Triangle& t, Index a, Index b, Index c) {
  for (int k = 0; k < 3; ++k) {
    if (t[k] == a && t[(k + 1) % 3] == b && t[(k + 2) % 3] == c) return true;
  }
  return false;
}

TEST(GapClosing, TheFrontLeavesTheGapWhenItsGabrielPointMayNotJoin) {
  const GapRun run = grow_around_gap(false);
  EXPECT_TRUE(run.grown.empty());
}

TEST(GapClosing, AThreeEdgeGapIsClosedFacingLikeItsNeighbours) {
  const GapRun run = grow_around_gap(true);
  ASSERT_EQ(run.grown.size(), 1u);
  // Opposite to the neighbours' traversals B->A, X->B, A->X, once its flip is applied.
  Triangle t = run.grown[0];
  if (run.flip[0]) std::swap(t[1], t[2]);
  EXPECT_TRUE(same_cycle(t, 0, 1, 2));
}

// A flat 5 x 5 grid of points, every cell triangulated but cell (1, 1), loaded before the run as
// a seam loads the live triangles at the points whose stars it sees whole; no point may grow.
// `fillable` per input point (empty: none but the growable ones). Returns the triangles the run
// added, as input indices.
std::vector<Triangle> fill_loaded_square_hole(const std::vector<std::uint8_t>& fillable) {
  std::vector<float> xyz;
  std::vector<Index> ids;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      xyz.insert(xyz.end(), {static_cast<float>(i), static_cast<float>(j), 0.0f});
      ids.push_back(static_cast<Index>(5 * i + j));
    }
  }
  const g2s::HashGrid grid(xyz, ids);
  std::vector<Index> at(25);
  for (std::uint32_t k = 0; k < grid.size(); ++k) at[grid.id(k)] = k;
  std::vector<Triangle> preload;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      if (i == 1 && j == 1) continue;
      const Index a = at[5 * i + j], b = at[5 * (i + 1) + j], c = at[5 * (i + 1) + j + 1],
                  d = at[5 * i + j + 1];
      preload.push_back({a, b, c});
      preload.push_back({a, c, d});
    }
  }
  const std::vector<std::uint32_t> labels(preload.size(), 0);
  const std::vector<std::uint8_t> growable(grid.size(), 0);
  std::vector<std::uint8_t> fill_at;
  if (!fillable.empty()) {
    fill_at.resize(grid.size());
    for (std::uint32_t k = 0; k < grid.size(); ++k) fill_at[k] = fillable[grid.id(k)];
  }
  const g2s::GrowResult r =
      g2s::grow_mesh(grid, g2s::MeshOptions{}, {preload, labels, growable, {}, 0, fill_at});
  std::vector<Triangle> added;
  for (const Triangle& t : r.triangles)
    added.push_back({grid.id(t[0]), grid.id(t[1]), grid.id(t[2])});
  return added;
}

TEST(HoleFilling, ARunFillsOverPointsItMayNotGrowFromWhereItSeesTheirWholeStars) {
  // The hole's corners: points 6, 11, 12 and 7.
  const std::vector<Triangle> filled = fill_loaded_square_hole(std::vector<std::uint8_t>(25, 1));
  ASSERT_EQ(filled.size(), 2u);
  for (const Triangle& t : filled) {
    for (const Index v : t) EXPECT_TRUE(v == 6 || v == 7 || v == 11 || v == 12) << v;
  }
  // Points that may neither grow nor fill (a seam's context before): the hole stays.
  EXPECT_TRUE(fill_loaded_square_hole({}).empty());
  // A loop with one corner the run may not fill stays open too.
  std::vector<std::uint8_t> but_one(25, 1);
  but_one[12] = 0;
  EXPECT_TRUE(fill_loaded_square_hole(but_one).empty());
}

TEST(GapClosing, AGapIsNotClosedWhereItWouldFold) {
  // A flat pyramid: three triangles around P, just above the centre of A B X, facing up. Its
  // open edges A->B, B->X, X->A make a three-edge gap, but the triangle closing it would face
  // down, a fold of nearly 180 degrees from each of them.
  const std::vector<float> xyz{0, 0, 0, 1, 0, 0, 0.5f, 0.866f, 0, 0.5f, 0.2887f, 0.1f};
  const std::vector<Index> ids{0, 1, 2, 3};
  const g2s::HashGrid grid(xyz, ids);
  std::array<Index, 4> at{};
  for (std::uint32_t k = 0; k < grid.size(); ++k) at[grid.id(k)] = k;
  const std::vector<Triangle> preload{
      {at[0], at[1], at[3]}, {at[1], at[2], at[3]}, {at[2], at[0], at[3]}};
  const std::vector<std::uint32_t> labels{0, 0, 0};
  const g2s::GrowResult r =
      g2s::grow_mesh(grid, g2s::MeshOptions{}, {preload, labels, {}, {}, 0, {}});
  EXPECT_TRUE(r.triangles.empty());
}

}  // namespace

// Scraps: a flat 24 x 24 patch (spacing 1, jittered) and three points in a small triangle
// `height` above its middle, out of the front's reach, so that they seed a lone triangle of
// their own. Returns the grown triangles (input indices); the lone triangle's points are
// 576-578.
std::vector<float> patch_with_lone_points(float height) {
  std::vector<float> xyz;
  std::uint32_t state = 12345;
  const auto jitter = [&state] {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / 16777216.0f * 0.2f - 0.1f;
  };
  for (int i = 0; i < 24; ++i) {
    for (int j = 0; j < 24; ++j) {
      xyz.insert(xyz.end(),
                 {static_cast<float>(i) + jitter(), static_cast<float>(j) + jitter(), 0});
    }
  }
  xyz.insert(xyz.end(), {11.2f, 11.3f, height, 12.1f, 11.4f, height, 11.6f, 12.2f, height});
  return xyz;
}

std::vector<Index> identity_ids(std::size_t count) {
  std::vector<Index> ids(count);
  for (std::size_t k = 0; k < count; ++k) ids[k] = static_cast<Index>(k);
  return ids;
}

std::vector<Triangle> grow_patch_with_lone_triangle(float height, int max_hole_rings) {
  const std::vector<float> xyz = patch_with_lone_points(height);
  const std::vector<Index> ids = identity_ids(xyz.size() / 3);
  const g2s::HashGrid grid(xyz, ids);
  g2s::MeshOptions options;
  options.max_hole_rings = max_hole_rings;
  const g2s::GrowResult r = g2s::grow_mesh(grid, options);
  std::vector<Triangle> out;
  for (const Triangle& t : r.triangles)
    out.push_back({grid.id(t[0]), grid.id(t[1]), grid.id(t[2])});
  return out;
}

bool has_lone_triangle(const std::vector<Triangle>& triangles) {
  return std::any_of(triangles.begin(), triangles.end(), [](const Triangle& t) {
    return std::all_of(t.begin(), t.end(), [](Index v) { return v >= 576; });
  });
}

bool uses_lone_points(const std::vector<Triangle>& triangles) {
  return std::any_of(triangles.begin(), triangles.end(), [](const Triangle& t) {
    return std::any_of(t.begin(), t.end(), [](Index v) { return v >= 576; });
  });
}

TEST(Scraps, ALoneTriangleNearTheSurfaceGoesAndItsPointsAreLeftOut) {
  // Without leaving points out (max_hole_rings 0) the lone triangle is there, so it did grow.
  ASSERT_TRUE(has_lone_triangle(grow_patch_with_lone_triangle(1.5f, 0)));
  const std::vector<Triangle> cleaned = grow_patch_with_lone_triangle(1.5f, 3);
  EXPECT_FALSE(uses_lone_points(cleaned));
  // The patch itself is untouched.
  EXPECT_EQ(cleaned.size() + 1, grow_patch_with_lone_triangle(1.5f, 0).size());
}

TEST(Scraps, ALoneTriangleFarFromTheSurfaceStays) {
  EXPECT_TRUE(has_lone_triangle(grow_patch_with_lone_triangle(6.0f, 3)));
}

// The patch and the lone triangle grown without leaving points out, then loaded before a
// second run (as a seam loads a tile's triangles; the lone one lost its neighbours in the tile's
// halo). `judge_corner` false: a corner of the lone triangle is a point the second run does not
// judge (a seam's context). Returns the loaded triangles the second run removed, as input
// indices, and how many triangles it added.
std::pair<std::vector<Triangle>, std::size_t> regrow_loaded_patch(bool judge_corner) {
  const std::vector<float> xyz = patch_with_lone_points(1.5f);
  const g2s::HashGrid grid(xyz, identity_ids(xyz.size() / 3));
  g2s::MeshOptions options;
  options.max_hole_rings = 0;
  const g2s::GrowResult first = g2s::grow_mesh(grid, options);
  std::vector<std::uint8_t> growable(grid.size(), 1);
  if (!judge_corner) {
    for (std::uint32_t k = 0; k < grid.size(); ++k) {
      if (grid.id(k) == 578) growable[k] = 0;
    }
  }
  options.max_hole_rings = 3;
  const g2s::GrowResult second =
      g2s::grow_mesh(grid, options, {first.triangles, first.group, growable, {}, 0, {}});
  std::vector<Triangle> removed;
  for (std::uint32_t k : second.removed_preload) {
    const Triangle& t = first.triangles[k];
    removed.push_back({grid.id(t[0]), grid.id(t[1]), grid.id(t[2])});
  }
  return {removed, second.triangles.size()};
}

TEST(Scraps, ALoadedLoneTriangleNearTheSurfaceGoesWhenTheRunJudgesEveryCorner) {
  const auto [removed, added] = regrow_loaded_patch(true);
  ASSERT_EQ(removed.size(), 1u);
  EXPECT_TRUE(has_lone_triangle(removed));
  EXPECT_EQ(added, 0u);
}

TEST(Scraps, ALoadedLoneTriangleWithACornerTheRunDoesNotJudgeStays) {
  const auto [removed, added] = regrow_loaded_patch(false);
  EXPECT_TRUE(removed.empty());
  EXPECT_EQ(added, 0u);
}

// Capping a piece's only loop (cap_single_loops): the four corners of a regular tetrahedron,
// and with `far_point` a fifth point far from them (so that the run is more than the piece and
// the point left over). Returns the grown triangles (input indices) as they face once their
// flips are applied.
std::vector<Triangle> grow_tetrahedron(const g2s::MeshOptions& options, bool far_point = false) {
  std::vector<float> xyz{1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
  std::vector<Index> ids{0, 1, 2, 3};
  if (far_point) {
    xyz.insert(xyz.end(), {30, 30, 30});
    ids.push_back(4);
  }
  const g2s::HashGrid grid(xyz, ids);
  const g2s::GrowResult r = g2s::grow_mesh(grid, options);
  std::vector<Triangle> out;
  for (std::size_t t = 0; t < r.triangles.size(); ++t) {
    Triangle tri{grid.id(r.triangles[t][0]), grid.id(r.triangles[t][1]),
                 grid.id(r.triangles[t][2])};
    if (r.flip[t]) std::swap(tri[1], tri[2]);
    out.push_back(tri);
  }
  return out;
}

TEST(Caps, TheFrontGrowsOneTriangleOfATetrahedron) {
  // Without hole filling nothing is capped: the fourth point lies behind the seed triangle,
  // where no search ball looks.
  g2s::MeshOptions options;
  options.max_hole_edges = 0;
  EXPECT_EQ(grow_tetrahedron(options).size(), 1u);
}

TEST(Caps, TheFourthPointClosesTheTetrahedronConsistentlyOriented) {
  const std::vector<Triangle> triangles = grow_tetrahedron(g2s::MeshOptions{});
  ASSERT_EQ(triangles.size(), 4u);
  // Closed and consistently oriented: every directed edge once, and its reverse once.
  std::vector<std::pair<Index, Index>> directed;
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) directed.push_back({t[k], t[(k + 1) % 3]});
  }
  std::sort(directed.begin(), directed.end());
  EXPECT_EQ(std::adjacent_find(directed.begin(), directed.end()), directed.end());
  for (const auto& [u, v] : directed) {
    EXPECT_TRUE(std::binary_search(directed.begin(), directed.end(), std::pair{v, u}));
  }
}

TEST(Caps, NoCapThatChoosesAPointFoldsBeyondMaxFold) {
  // The regular tetrahedron's neighbouring faces' normals are 109.5 degrees apart. With another
  // point in the run the fan chooses its point, as growth does, under growth's fold limit.
  g2s::MeshOptions options;
  options.max_fold_deg = 100;
  EXPECT_EQ(grow_tetrahedron(options, true).size(), 1u);
  EXPECT_EQ(grow_tetrahedron(g2s::MeshOptions{}, true).size(), 4u);
  // The tetrahedron alone: the point left over is the only one, and like a hole's filling the
  // fan is held to no fold limit.
  EXPECT_EQ(grow_tetrahedron(options).size(), 4u);
}
