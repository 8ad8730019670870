// Tests of the post-processing of a grown mesh (src/cleanup/cleanup.hpp, docs/algorithm.md §5):
// non-manifold vertex removal on hand-made fans whose answer is known, on a cascade, on random
// damage to a closed surface, and the orientation of whole components, each through the calls
// the pipeline makes (mark_non_manifold_fans, group_flips).
#include "cleanup/cleanup.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "g2s/stats.hpp"

namespace {

using g2s::Index;
using g2s::IndexedMesh;
using g2s::Triangle;
using g2s::Vec3;
using g2s::Vec3f;

using Points = std::vector<std::array<double, 3>>;

IndexedMesh as_mesh(const Points& points, const std::vector<Triangle>& triangles) {
  IndexedMesh mesh;
  for (const auto& p : points) mesh.xyz.insert(mesh.xyz.end(), p.begin(), p.end());
  mesh.triangles = triangles;
  return mesh;
}

std::vector<Vec3f> as_floats(const Points& points) {
  std::vector<Vec3f> out;
  for (const auto& p : points) {
    out.push_back({static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])});
  }
  return out;
}

// Distinct, generic positions: no three collinear, so no triangle is degenerate for compute_stats.
Points generic_points(std::size_t n, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Points p(n);
  for (auto& q : p) q = {u(rng), u(rng), u(rng)};
  return p;
}

const Points kOctahedronPoints{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
// Outward (counter-clockwise seen from outside).
const std::vector<Triangle> kOctahedron{{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                        {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};

std::vector<Triangle> reversed(std::vector<Triangle> t) {
  for (auto& tri : t) std::swap(tri[1], tri[2]);
  return t;
}

std::vector<Triangle> shifted(std::vector<Triangle> t, Index by) {
  for (auto& tri : t) {
    for (Index& v : tri) v += by;
  }
  return t;
}

std::vector<Triangle> concat(std::initializer_list<std::vector<Triangle>> parts) {
  std::vector<Triangle> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

g2s::MeshStats stats_of(const Points& points, const std::vector<Triangle>& triangles) {
  return g2s::compute_stats(as_mesh(points, triangles));
}

double signed_volume(const std::vector<Triangle>& triangles, const std::vector<Vec3f>& pos) {
  double v = 0;
  for (const Triangle& t : triangles) {
    v += dot(Vec3(pos[t[0]]), cross(Vec3(pos[t[1]]), Vec3(pos[t[2]])));
  }
  return v / 6;
}

Vec3 normal_of(const Triangle& t, const std::vector<Vec3f>& pos) {
  const Vec3 a(pos[t[0]]), b(pos[t[1]]), c(pos[t[2]]);
  return cross(b - a, c - a);
}

// The clean-up as the pipeline runs it (the grower, grow_tile and the stitcher's release):
// mark_non_manifold_fans with every vertex a suspect and every star finished; the marked
// triangles are then erased, the others keep their order.
g2s::NonManifoldReport remove_extra_fans(std::vector<Triangle>& tris, std::size_t vertex_count) {
  std::vector<Index> every(vertex_count);
  std::iota(every.begin(), every.end(), Index{0});
  std::vector<std::uint8_t> dead;
  std::vector<Index> deferred;
  const g2s::NonManifoldReport report =
      g2s::mark_non_manifold_fans(tris, vertex_count, every, {}, dead, deferred);
  EXPECT_TRUE(deferred.empty());
  EXPECT_EQ(report.vertices_unjudged, 0u);
  std::size_t kept = 0;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    if (!dead[t]) tris[kept++] = tris[t];
  }
  tris.resize(kept);
  return report;
}

// Orients `tris` as the stitcher does: each triangle is an orientation group of its own with its
// sums (GroupSums' fields, positions from the origin), groups whose triangles share an edge are
// joined (parity 1 where both run along the edge the same way), and group_flips turns each
// component as a whole. Returns the number of components reversed.
std::uint64_t orient_as_stitched(std::vector<Triangle>& tris, const std::vector<Vec3f>& pos) {
  g2s::ParityUnionFind groups;
  std::vector<g2s::GroupSums> sums(tris.size());
  std::map<std::pair<Index, Index>, std::pair<std::uint32_t, bool>> first_use;
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    groups.add();
    const Triangle& c = tris[t];
    const Vec3 a(pos[c[0]]), b(pos[c[1]]), d(pos[c[2]]);
    sums[t].det = dot(a, cross(b, d));
    sums[t].normal = cross(b - a, d - a);
    sums[t].centroid = a + b + d;
    sums[t].corners = 3;
    sums[t].edge_keys =
        g2s::edge_key(c[0], c[1]) ^ g2s::edge_key(c[1], c[2]) ^ g2s::edge_key(c[2], c[0]);
    for (int k = 0; k < 3; ++k) {
      const Index u = c[k], v = c[(k + 1) % 3];
      const auto [at, fresh] = first_use.try_emplace(std::minmax(u, v), t, u < v);
      if (!fresh) {
        EXPECT_TRUE(groups.unite(at->second.first, t, at->second.second == (u < v)));
      }
    }
  }
  std::uint64_t flipped = 0;
  const std::vector<std::uint8_t> flip = g2s::group_flips(groups, sums, true, flipped);
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    if (flip[t]) std::swap(tris[t][1], tris[t][2]);
  }
  return flipped;
}

// --- non-manifold vertices ----------------------------------------------------------------------

TEST(NonManifoldRemoval, TypeIExtraTriangleTouchingAClosedFanIsRemoved) {
  Points points = kOctahedronPoints;
  points.push_back({2, 0.5, 0.3});
  points.push_back({2, -0.5, 0.2});
  for (const bool extra_first : {false, true}) {
    const std::vector<Triangle> extra{{0, 6, 7}};
    std::vector<Triangle> tris =
        extra_first ? concat({extra, kOctahedron}) : concat({kOctahedron, extra});
    const g2s::MeshStats before = stats_of(points, tris);
    ASSERT_EQ(before.non_manifold_vertices_type1, 1u);
    const auto report = remove_extra_fans(tris, points.size());
    EXPECT_EQ(tris, kOctahedron) << "extra first: " << extra_first;
    EXPECT_EQ(report.vertices_fixed, 1u);
    EXPECT_EQ(report.triangles_removed, 1u);
    EXPECT_EQ(stats_of(points, tris).non_manifold_vertices, 0u);
  }
}

TEST(NonManifoldRemoval, TypeIKeepsTheClosedFanEvenWhenAnOpenFanIsLarger) {
  // Vertex 0 of the octahedron (closed fan of 4) also carries an open fan of 6 triangles.
  Points points = kOctahedronPoints;
  std::vector<Triangle> open_fan;
  for (int k = 0; k <= 6; ++k) {
    const double t = 0.3 * k;
    points.push_back({2 + 0.1 * k, std::cos(t), std::sin(t)});
    if (k > 0) open_fan.push_back({0, static_cast<Index>(5 + k), static_cast<Index>(6 + k)});
  }
  std::vector<Triangle> tris = concat({open_fan, kOctahedron});
  ASSERT_EQ(stats_of(points, tris).non_manifold_vertices_type1, 1u);
  const auto report = remove_extra_fans(tris, points.size());
  EXPECT_EQ(tris, kOctahedron);
  EXPECT_EQ(report.triangles_removed, 6u);
  EXPECT_EQ(stats_of(points, tris).non_manifold_vertices, 0u);
}

TEST(NonManifoldRemoval, TypeIITheSmallerOfTwoOpenFansIsRemoved) {
  // Vertex 0: fan A = 2 triangles over 1-2-3, fan B = 3 triangles over 4-5-6-7.
  const Points points = generic_points(8, 3);
  const std::vector<Triangle> a1{{0, 1, 2}}, a2{{0, 2, 3}};
  const std::vector<Triangle> b1{{0, 4, 5}}, b2{{0, 5, 6}}, b3{{0, 6, 7}};
  for (const bool small_first : {true, false}) {
    std::vector<Triangle> tris =
        small_first ? concat({a1, b1, a2, b2, b3}) : concat({b1, b2, a1, b3, a2});
    const g2s::MeshStats before = stats_of(points, tris);
    ASSERT_EQ(before.non_manifold_vertices_type2, 1u);
    ASSERT_EQ(before.non_manifold_vertices, 1u);
    const auto report = remove_extra_fans(tris, points.size());
    EXPECT_EQ(tris, concat({b1, b2, b3})) << "small first: " << small_first;
    EXPECT_EQ(report.vertices_fixed, 1u);
    EXPECT_EQ(report.triangles_removed, 2u);
    EXPECT_EQ(stats_of(points, tris).non_manifold_vertices, 0u);
  }
}

TEST(NonManifoldRemoval, CascadeWhenRemovingAFanSplitsAnAlreadyVisitedVertex) {
  // Vertex 11 has fans A = {A1, A2} and B = {B1, B2, B3}: A goes. A1 and A2 sit in the middle of
  // vertex 2's single open fan X2-X1-A1-A2-Y; without them vertex 2 (visited earlier, manifold
  // then) has fans {X1, X2} and {Y}, so Y must go too.
  const Points points = generic_points(12, 5);
  const Triangle a1{11, 1, 2}, a2{11, 2, 3};
  const Triangle b1{11, 4, 5}, b2{11, 5, 6}, b3{11, 6, 7};
  const Triangle x1{2, 1, 0}, x2{2, 0, 8}, y{3, 2, 10};
  std::vector<Triangle> tris{x1, a1, b1, y, a2, b2, x2, b3};
  const g2s::MeshStats before = stats_of(points, tris);
  ASSERT_EQ(before.non_manifold_vertices, 1u);
  ASSERT_EQ(before.orientation_conflicts, 0u);
  const auto report = remove_extra_fans(tris, points.size());
  EXPECT_EQ(tris, (std::vector<Triangle>{x1, b1, b2, x2, b3}));
  EXPECT_EQ(report.vertices_fixed, 2u);
  EXPECT_EQ(report.triangles_removed, 3u);
  EXPECT_EQ(stats_of(points, tris).non_manifold_vertices, 0u);
}

// A closed torus of nu x nv quads, two triangles each, consistently oriented outward.
struct Torus {
  Points points;
  std::vector<Triangle> triangles;
};

Torus torus(int nu, int nv) {
  Torus t;
  const double pi = std::numbers::pi;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const double u = 2 * pi * i / nu, v = 2 * pi * j / nv;
      t.points.push_back(
          {(3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u), std::sin(v)});
    }
  }
  auto id = [&](int i, int j) { return static_cast<Index>((j % nv) * nu + (i % nu)); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      t.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return t;
}

bool is_subsequence(const std::vector<Triangle>& sub, const std::vector<Triangle>& full) {
  std::size_t k = 0;
  for (const Triangle& t : full) {
    if (k < sub.size() && sub[k] == t) ++k;
  }
  return k == sub.size();
}

TEST(NonManifoldRemoval, RandomlyDamagedTorusEndsWithoutNonManifoldVertices) {
  const Torus base = torus(40, 20);
  ASSERT_EQ(stats_of(base.points, base.triangles).non_manifold_vertices, 0u);
  std::uint64_t fixed_total = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    std::mt19937_64 rng(seed);
    const unsigned drop_percent = 20 + static_cast<unsigned>(seed % 4) * 10;  // 20..50%
    std::vector<Triangle> damaged;
    for (const Triangle& t : base.triangles) {
      if (rng() % 100 >= drop_percent) damaged.push_back(t);
    }
    const g2s::MeshStats before = stats_of(base.points, damaged);
    std::vector<Triangle> tris = damaged;
    const auto report = remove_extra_fans(tris, base.points.size());
    const g2s::MeshStats after = stats_of(base.points, tris);
    EXPECT_EQ(after.non_manifold_vertices, 0u) << "seed " << seed;
    EXPECT_EQ(after.non_manifold_edges, 0u);
    EXPECT_EQ(after.orientation_conflicts, 0u);
    EXPECT_EQ(report.triangles_removed, damaged.size() - tris.size());
    EXPECT_GE(report.vertices_fixed, before.non_manifold_vertices > 0 ? 1u : 0u);
    EXPECT_TRUE(is_subsequence(tris, damaged)) << "survivors must keep their order";
    // A second pass has nothing left to do.
    std::vector<Triangle> again = tris;
    const auto second = remove_extra_fans(again, base.points.size());
    EXPECT_EQ(second.triangles_removed, 0u);
    EXPECT_EQ(again, tris);
    fixed_total += report.vertices_fixed;
  }
  EXPECT_GT(fixed_total, 100u);  // the damage did create plenty of bow-ties to fix
}

TEST(NonManifoldRemoval, FewSuspectsOnALargeMeshAreJudgedFromTheirOwnStars) {
  // As in the grower: a large mesh, and as suspects only the corners of the triangles removed.
  // Two triangles of a vertex's star that share no edge at it are removed at 25 vertices far
  // apart, each then a bow-tie of two open fans. Few suspects, so only their stars (and their
  // neighbours') are built; every bow-tie must still be undone.
  constexpr int nu = 200, nv = 100;
  const Torus base = torus(nu, nv);
  std::vector<std::uint8_t> drop(base.triangles.size(), 0);
  for (int i = 5; i < nu; i += 40) {
    for (int j = 5; j < nv; j += 20) {
      drop[static_cast<std::size_t>(2 * (j * nu + i))] = 1;              // quad (i, j), first half
      drop[static_cast<std::size_t>(2 * ((j - 1) * nu + (i - 1)))] = 1;  // quad (i-1, j-1)
    }
  }
  std::vector<Triangle> tris;
  std::vector<Index> suspects;
  for (std::size_t t = 0; t < base.triangles.size(); ++t) {
    if (!drop[t]) {
      tris.push_back(base.triangles[t]);
    } else {
      suspects.insert(suspects.end(), base.triangles[t].begin(), base.triangles[t].end());
    }
  }
  ASSERT_LT(suspects.size() * 64, base.points.size()) << "few enough suspects to build lazily";
  ASSERT_EQ(stats_of(base.points, tris).non_manifold_vertices, 25u);
  std::vector<std::uint8_t> dead;
  std::vector<Index> deferred;
  const g2s::NonManifoldReport report =
      g2s::mark_non_manifold_fans(tris, base.points.size(), suspects, {}, dead, deferred);
  std::vector<Triangle> kept;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    if (!dead[t]) kept.push_back(tris[t]);
  }
  EXPECT_EQ(report.vertices_fixed, 25u);
  EXPECT_EQ(report.triangles_removed, tris.size() - kept.size());
  EXPECT_EQ(stats_of(base.points, kept).non_manifold_vertices, 0u);
  EXPECT_EQ(stats_of(base.points, kept).non_manifold_edges, 0u);
}

TEST(NonManifoldRemoval, ManifoldMeshesAreLeftUntouched) {
  // Closed octahedron + closed torus + an open torus strip with a hole: all manifold.
  const Torus t = torus(24, 12);
  Points points = kOctahedronPoints;
  points.insert(points.end(), t.points.begin(), t.points.end());
  std::vector<Triangle> strip;
  for (std::size_t k = 0; k < t.triangles.size(); ++k) {
    if (k < 2 * 24 * 3 && k != 78 && k != 79) strip.push_back(t.triangles[k]);  // 3 rows, 1 hole
  }
  const std::vector<Triangle> torus_part = shifted(t.triangles, 6);
  Points more = t.points;
  for (auto& p : more) p[2] += 10;  // the strip, on its own copy of the torus points
  points.insert(points.end(), more.begin(), more.end());
  const std::vector<Triangle> strip_part = shifted(strip, static_cast<Index>(6 + t.points.size()));
  std::vector<Triangle> tris = concat({kOctahedron, torus_part, strip_part});
  ASSERT_EQ(stats_of(points, tris).non_manifold_vertices, 0u);
  const std::vector<Triangle> original = tris;
  const auto report = remove_extra_fans(tris, points.size());
  EXPECT_EQ(tris, original);
  EXPECT_EQ(report.vertices_fixed, 0u);
  EXPECT_EQ(report.triangles_removed, 0u);
}

TEST(NonManifoldRemoval, EmptyInputAndUnusedVerticesAreFine) {
  std::vector<Triangle> none;
  const auto report = remove_extra_fans(none, 100);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(report.triangles_removed, 0u);
}

TEST(NonManifoldRemoval, UnfinishedCornersAreDeferredAndBrokenStarsCounted) {
  // Vertex 0: fan A = {a1, a2} over 1-2-3 goes, fan B = {b1, b2, b3} stays. Of the corners A's
  // deletion may split, 1 is not finished yet (deferred, to be judged later), 2 is judged now and
  // 3's star is no longer whole (counted as unjudged).
  const std::vector<Triangle> tris{{0, 1, 2}, {0, 2, 3}, {0, 4, 5}, {0, 5, 6}, {0, 6, 7}};
  std::vector<std::uint8_t> finished(8, 1);
  finished[1] = 0;
  finished[3] = 2;
  const std::vector<Index> suspects{0};
  std::vector<std::uint8_t> dead;
  std::vector<Index> deferred;
  const g2s::NonManifoldReport report =
      g2s::mark_non_manifold_fans(tris, 8, suspects, finished, dead, deferred);
  EXPECT_EQ(dead, (std::vector<std::uint8_t>{1, 1, 0, 0, 0}));
  EXPECT_EQ(deferred, std::vector<Index>{1});
  EXPECT_EQ(report.vertices_fixed, 1u);
  EXPECT_EQ(report.triangles_removed, 2u);
  EXPECT_EQ(report.vertices_unjudged, 1u);
}

// --- orientation --------------------------------------------------------------------------------

TEST(OrientComponents, InwardOctahedronIsFlippedOutward) {
  const std::vector<Vec3f> pos = as_floats(kOctahedronPoints);
  std::vector<Triangle> tris = reversed(kOctahedron);
  ASSERT_LT(signed_volume(tris, pos), 0);
  EXPECT_EQ(orient_as_stitched(tris, pos), 1u);
  EXPECT_GT(signed_volume(tris, pos), 0);
  EXPECT_EQ(tris, kOctahedron);
}

TEST(OrientComponents, TrianglesGrownInDisagreementAreMadeConsistentAndOutward) {
  // Seeds of either orientation met in one component: the parity of the joined groups turns
  // every triangle to agree, then the component faces outward.
  const std::vector<Vec3f> pos = as_floats(kOctahedronPoints);
  for (const std::vector<std::size_t>& turned :
       {std::vector<std::size_t>{0, 5}, {1, 2, 3}, {0, 1, 2, 3, 4, 6}}) {
    std::vector<Triangle> tris = kOctahedron;
    for (std::size_t t : turned) std::swap(tris[t][1], tris[t][2]);
    orient_as_stitched(tris, pos);
    EXPECT_EQ(tris, kOctahedron) << turned.size() << " turned";
  }
}

TEST(OrientComponents, OutwardOctahedronIsLeftAlone) {
  const std::vector<Vec3f> pos = as_floats(kOctahedronPoints);
  std::vector<Triangle> tris = kOctahedron;
  EXPECT_EQ(orient_as_stitched(tris, pos), 0u);
  EXPECT_EQ(tris, kOctahedron);
}

TEST(OrientComponents, ComponentsAreOrientedIndependently) {
  // Three octahedra far from the origin (so a volume taken about the origin would mislead):
  // inward, outward, inward, interleaved in the triangle list.
  Points points;
  for (int c = 0; c < 3; ++c) {
    for (const auto& p : kOctahedronPoints) points.push_back({p[0] + 10 + 5 * c, p[1] + 7, p[2]});
  }
  const std::vector<Vec3f> pos = as_floats(points);
  const std::vector<Triangle> parts[3] = {reversed(kOctahedron), shifted(kOctahedron, 6),
                                          shifted(reversed(kOctahedron), 12)};
  std::vector<Triangle> tris;
  for (std::size_t k = 0; k < kOctahedron.size(); ++k) {
    for (const auto& part : parts) tris.push_back(part[k]);
  }
  EXPECT_EQ(orient_as_stitched(tris, pos), 2u);
  for (Index c = 0; c < 3; ++c) {
    std::vector<Triangle> mine;
    for (const Triangle& t : tris) {
      if (t[0] / 6 == c) mine.push_back(t);
    }
    ASSERT_EQ(mine.size(), 8u);
    EXPECT_EQ(mine, shifted(kOctahedron, 6 * c)) << "component " << c;
    EXPECT_GT(signed_volume(mine, pos), 0) << "component " << c;
  }
}

// An open nx x ny height-field patch over [0, nx] x [0, ny] with gentle hills, facing +z.
void height_patch(int nx, int ny, double x0, Points& points, std::vector<Triangle>& tris) {
  const auto base = static_cast<Index>(points.size());
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      points.push_back({x0 + i, double(j), 0.3 * std::sin(0.7 * i) * std::cos(0.5 * j)});
    }
  }
  auto id = [&](int i, int j) { return base + static_cast<Index>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
}

TEST(OrientComponents, OpenHorizontalPatchFacingDownIsFlippedUp) {
  Points points;
  std::vector<Triangle> up;
  height_patch(12, 9, 0.0, points, up);
  const std::vector<Vec3f> pos = as_floats(points);
  std::vector<Triangle> tris = reversed(up);
  for (const Triangle& t : tris) ASSERT_LT(normal_of(t, pos).z, 0);
  EXPECT_EQ(orient_as_stitched(tris, pos), 1u);
  EXPECT_EQ(tris, up);
  for (const Triangle& t : tris) EXPECT_GT(normal_of(t, pos).z, 0);
  // Facing up already: nothing to do.
  EXPECT_EQ(orient_as_stitched(tris, pos), 0u);
  EXPECT_EQ(tris, up);
}

TEST(OrientComponents, TwoOpenPatchesOneDownOneUpOnlyTheDownOneFlips) {
  Points points;
  std::vector<Triangle> first, second;
  height_patch(8, 8, 0.0, points, first);
  height_patch(8, 8, 20.0, points, second);
  const std::vector<Vec3f> pos = as_floats(points);
  std::vector<Triangle> tris = concat({second, reversed(first)});
  EXPECT_EQ(orient_as_stitched(tris, pos), 1u);
  EXPECT_EQ(tris, concat({second, first}));
}

TEST(OrientComponents, OpenVerticalCylinderFacingInwardIsFlippedOutward) {
  // A tube without caps: its mean normal is about zero, so "up" means nothing; it must face away
  // from its axis.
  Points points;
  const int nu = 32, nv = 6;
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const double u = 2 * std::numbers::pi * i / nu;
      points.push_back({4 + std::cos(u), -3 + std::sin(u), 0.25 * j});
    }
  }
  auto id = [&](int i, int j) { return static_cast<Index>(j * nu + (i % nu)); };
  std::vector<Triangle> outward;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      outward.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      outward.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  const std::vector<Vec3f> pos = as_floats(points);
  for (const Triangle& t : outward) {  // the construction faces away from the axis (4, -3)
    const Vec3 c = (Vec3(pos[t[0]]) + Vec3(pos[t[1]]) + Vec3(pos[t[2]])) * (1.0 / 3);
    ASSERT_GT(dot(normal_of(t, pos), Vec3{c.x - 4, c.y + 3, 0}), 0);
  }
  std::vector<Triangle> tris = reversed(outward);
  EXPECT_EQ(orient_as_stitched(tris, pos), 1u);
  EXPECT_EQ(tris, outward);
}

TEST(OrientComponents, MixedClosedAndOpenComponents) {
  // An inward octahedron next to a downward patch: both flipped, each by its own rule.
  Points points = kOctahedronPoints;
  std::vector<Triangle> patch;
  height_patch(6, 6, 10.0, points, patch);
  const std::vector<Vec3f> pos = as_floats(points);
  std::vector<Triangle> tris = concat({reversed(patch), reversed(kOctahedron)});
  EXPECT_EQ(orient_as_stitched(tris, pos), 2u);
  EXPECT_EQ(tris, concat({patch, kOctahedron}));
}

}  // namespace
