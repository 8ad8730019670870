// Tests of compute_stats (docs/algorithm.md §9, "Measuring a mesh") on small hand-made meshes whose
// answers are known by hand, plus grids whose answers follow from their topology, the JSON/text
// forms and the `g2s stats` command line.
#include "g2s/stats.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "g2s/error.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

using g2s::Index;
using g2s::IndexedMesh;
using g2s::MeshStats;
using g2s::Triangle;

IndexedMesh make_mesh(const std::vector<std::array<double, 3>>& vertices,
                      const std::vector<Triangle>& triangles) {
  IndexedMesh mesh;
  for (const auto& v : vertices) mesh.xyz.insert(mesh.xyz.end(), v.begin(), v.end());
  mesh.triangles = triangles;
  return mesh;
}

// The same mesh as a triangle soup: three fresh vertices per triangle, as STL stores it.
IndexedMesh unweld(const IndexedMesh& mesh) {
  IndexedMesh soup;
  for (const Triangle& t : mesh.triangles) {
    Triangle s{};
    for (int c = 0; c < 3; ++c) {
      s[c] = static_cast<Index>(soup.vertex_count());
      for (int k = 0; k < 3; ++k) soup.xyz.push_back(mesh.xyz[3 * std::size_t{t[c]} + k]);
    }
    soup.triangles.push_back(s);
  }
  return soup;
}

// Appends `part` to `mesh`, shifted by `offset`.
void append(IndexedMesh& mesh, const IndexedMesh& part, std::array<double, 3> offset) {
  const auto base = static_cast<Index>(mesh.vertex_count());
  for (std::size_t i = 0; i < part.xyz.size(); ++i) mesh.xyz.push_back(part.xyz[i] + offset[i % 3]);
  for (const Triangle& t : part.triangles)
    mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

IndexedMesh tetrahedron() {
  return make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                   {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
}

IndexedMesh octahedron() {
  return make_mesh(
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

IndexedMesh square() {
  return make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}});
}

// An nx x ny grid of quads, two triangles each, consistently oriented, with the quads for which
// skip(i, j) is true left out. wrap_x/wrap_y glue opposite sides (a cylinder, a torus), laid out
// in 3D so no two vertices coincide.
template <typename Skip>
IndexedMesh grid(int nx, int ny, bool wrap_x, bool wrap_y, Skip skip) {
  IndexedMesh mesh;
  const int vx = wrap_x ? nx : nx + 1;
  const int vy = wrap_y ? ny : ny + 1;
  const double pi = std::acos(-1.0);
  for (int j = 0; j < vy; ++j) {
    for (int i = 0; i < vx; ++i) {
      double x = i, y = j, z = 0;
      if (wrap_x && wrap_y) {  // torus
        const double u = 2 * pi * i / nx, v = 2 * pi * j / ny;
        x = (3 + std::cos(v)) * std::cos(u);
        y = (3 + std::cos(v)) * std::sin(u);
        z = std::sin(v);
      } else if (wrap_x) {  // cylinder
        const double u = 2 * pi * i / nx;
        x = std::cos(u);
        y = std::sin(u);
        z = j;
      }
      mesh.xyz.insert(mesh.xyz.end(), {x, y, z});
    }
  }
  auto id = [&](int i, int j) { return static_cast<Index>((j % vy) * vx + (i % vx)); };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (skip(i, j)) continue;
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return mesh;
}

IndexedMesh grid(int nx, int ny, bool wrap_x = false, bool wrap_y = false) {
  return grid(nx, ny, wrap_x, wrap_y, [](int, int) { return false; });
}

// Every field, for comparing two results in one go with a readable failure.
std::string all_fields(const MeshStats& s) {
  return g2s::stats_to_json(s);
}

void expect_clean(const MeshStats& s) {
  EXPECT_EQ(s.degenerate_triangles, 0u);
  EXPECT_EQ(s.duplicate_triangles, 0u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_EQ(s.non_manifold_vertices, 0u);
  EXPECT_EQ(s.non_manifold_vertices_type1, 0u);
  EXPECT_EQ(s.non_manifold_vertices_type2, 0u);
  EXPECT_EQ(s.orientation_conflicts, 0u);
}

TEST(Stats, EmptyMesh) {
  const MeshStats s = g2s::compute_stats(IndexedMesh{});
  EXPECT_EQ(s.triangles, 0u);
  EXPECT_EQ(s.vertices, 0u);
  EXPECT_EQ(s.components, 0u);
  EXPECT_EQ(s.holes, 0u);
  EXPECT_FALSE(s.has_coverage);
}

TEST(Stats, ClosedTetrahedron) {
  const MeshStats s = g2s::compute_stats(tetrahedron());
  EXPECT_EQ(s.triangles, 4u);
  EXPECT_EQ(s.vertices, 4u);
  expect_clean(s);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.holes, 0u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, ClosedOctahedron) {
  const MeshStats s = g2s::compute_stats(octahedron());
  EXPECT_EQ(s.triangles, 8u);
  EXPECT_EQ(s.vertices, 6u);
  expect_clean(s);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.holes, 0u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, SingleTriangle) {
  const MeshStats s = g2s::compute_stats(make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}));
  EXPECT_EQ(s.triangles, 1u);
  EXPECT_EQ(s.vertices, 3u);
  expect_clean(s);
  EXPECT_EQ(s.boundary_edges, 3u);
  EXPECT_EQ(s.holes, 1u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, SquareOfTwoTriangles) {
  const MeshStats s = g2s::compute_stats(square());
  EXPECT_EQ(s.triangles, 2u);
  EXPECT_EQ(s.vertices, 4u);
  expect_clean(s);
  EXPECT_EQ(s.boundary_edges, 4u);
  EXPECT_EQ(s.holes, 1u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, GridWithSquareHole) {
  // 4 x 4 quads, the middle 2 x 2 cut out: outer loop of 16 edges, inner loop of 8.
  const IndexedMesh mesh =
      grid(4, 4, false, false, [](int i, int j) { return i >= 1 && i <= 2 && j >= 1 && j <= 2; });
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.triangles, 24u);
  EXPECT_EQ(s.vertices, 24u);  // the centre vertex is used by no triangle
  expect_clean(s);
  EXPECT_EQ(s.boundary_edges, 24u);
  EXPECT_EQ(s.holes, 2u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, TwoHolesTouchingAtOneVertex) {
  // Quads (1,1) and (2,2) of a 4 x 4 grid cut out: two inner loops meeting at vertex (2,2),
  // which becomes a type II non-manifold vertex. Cycle rank: outer + 2 inner = 3.
  const IndexedMesh mesh = grid(
      4, 4, false, false, [](int i, int j) { return (i == 1 && j == 1) || (i == 2 && j == 2); });
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.boundary_edges, 16u + 8u);
  EXPECT_EQ(s.holes, 3u);
  EXPECT_EQ(s.non_manifold_vertices, 1u);
  EXPECT_EQ(s.non_manifold_vertices_type2, 1u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_EQ(s.orientation_conflicts, 0u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, BoundaryLoopsTouchingAtOneVertex) {
  // A bowtie: two triangles sharing only vertex 0; its boundary graph is two triangles joined at
  // that vertex (6 edges, 5 vertices, 1 component): cycle rank 2.
  const IndexedMesh mesh =
      make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}}, {{0, 1, 2}, {0, 3, 4}});
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.vertices, 5u);
  EXPECT_EQ(s.boundary_edges, 6u);
  EXPECT_EQ(s.holes, 2u);
  EXPECT_EQ(s.components, 1u);
  EXPECT_EQ(s.non_manifold_vertices, 1u);
  EXPECT_EQ(s.non_manifold_vertices_type1, 0u);
  EXPECT_EQ(s.non_manifold_vertices_type2, 1u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
}

TEST(Stats, TwoTetrahedraSharingAVertexIsTypeOne) {
  IndexedMesh mesh = tetrahedron();
  append(mesh, tetrahedron(), {0, 0, 1});  // its vertex 0 lands on the first's vertex 3
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.triangles, 8u);
  EXPECT_EQ(s.vertices, 7u);
  EXPECT_EQ(s.non_manifold_vertices, 1u);
  EXPECT_EQ(s.non_manifold_vertices_type1, 1u);
  EXPECT_EQ(s.non_manifold_vertices_type2, 0u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.holes, 0u);
  EXPECT_EQ(s.orientation_conflicts, 0u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, ClosedFanAndOpenFanIsTypeOne) {
  IndexedMesh mesh = tetrahedron();  // vertex 3 is at (0, 0, 1)
  mesh.xyz.insert(mesh.xyz.end(), {1, 1, 2, -1, 1, 2});
  mesh.triangles.push_back({3, 4, 5});
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.non_manifold_vertices, 1u);
  EXPECT_EQ(s.non_manifold_vertices_type1, 1u);
  EXPECT_EQ(s.boundary_edges, 3u);
  EXPECT_EQ(s.holes, 1u);
}

TEST(Stats, TwoOpenFansAtOneVertexIsTypeTwo) {
  // Two fans of two triangles each around vertex 0, touching only there.
  const IndexedMesh mesh =
      make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 0, 0}, {-1, -1, 0}, {0, -1, 0}},
                {{0, 1, 2}, {0, 2, 3}, {0, 4, 5}, {0, 5, 6}});
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.non_manifold_vertices, 1u);
  EXPECT_EQ(s.non_manifold_vertices_type1, 0u);
  EXPECT_EQ(s.non_manifold_vertices_type2, 1u);
  EXPECT_EQ(s.boundary_edges, 8u);
  EXPECT_EQ(s.holes, 2u);
  EXPECT_EQ(s.components, 1u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
}

TEST(Stats, ThreeTrianglesOnOneEdge) {
  const IndexedMesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                                     {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.non_manifold_edges, 1u);
  EXPECT_EQ(s.boundary_edges, 6u);
  EXPECT_EQ(s.orientation_conflicts, 0u);  // only 2-triangle edges can conflict
  // Edges in 3 triangles join no fans: both ends of the edge see three open fans.
  EXPECT_EQ(s.non_manifold_vertices, 2u);
  EXPECT_EQ(s.non_manifold_vertices_type2, 2u);
  EXPECT_EQ(s.holes, 2u);  // 6 boundary edges, 5 vertices, 1 component
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, FlippedTriangleGivesThreeOrientationConflicts) {
  IndexedMesh mesh = tetrahedron();
  std::swap(mesh.triangles[3][1], mesh.triangles[3][2]);
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.orientation_conflicts, 3u);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_EQ(s.non_manifold_vertices, 0u);
  EXPECT_EQ(s.holes, 0u);
  EXPECT_EQ(s.components, 1u);
}

TEST(Stats, DuplicatesInBothOrientations) {
  IndexedMesh mesh = square();
  mesh.triangles.push_back({1, 2, 0});  // same orientation, rotated
  mesh.triangles.push_back({2, 1, 0});  // reversed
  mesh.triangles.push_back({0, 3, 2});  // the other triangle, reversed
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.triangles, 5u);
  EXPECT_EQ(s.duplicate_triangles, 3u);
  // Left out of edge, vertex and fan counts: the rest is the plain square.
  MeshStats expected = g2s::compute_stats(square());
  expected.triangles = 5;
  expected.duplicate_triangles = 3;
  EXPECT_EQ(all_fields(s), all_fields(expected));

  // The first copy in input order is the one kept: a reversed copy listed first makes the shared
  // edge 0-2 an orientation conflict.
  IndexedMesh reversed_first = square();
  reversed_first.triangles.insert(reversed_first.triangles.begin(), Triangle{2, 1, 0});
  const MeshStats r = g2s::compute_stats(reversed_first);
  EXPECT_EQ(r.duplicate_triangles, 1u);
  EXPECT_EQ(r.orientation_conflicts, 1u);
  EXPECT_EQ(r.boundary_edges, 4u);
}

TEST(Stats, DegenerateTriangles) {
  IndexedMesh mesh = square();
  mesh.xyz.insert(mesh.xyz.end(), {0.5, 0, 0});   // 4: on edge 0-1
  mesh.xyz.insert(mesh.xyz.end(), {-0.0, 0, 0});  // 5: vertex 0 again (welded, -0 == 0)
  mesh.xyz.insert(mesh.xyz.end(), {9, 9, 9});     // 6: used only by a degenerate triangle
  mesh.triangles.push_back({0, 0, 1});            // repeated corner
  mesh.triangles.push_back({0, 4, 1});            // three collinear corners
  mesh.triangles.push_back({0, 5, 2});            // repeated corner after welding
  mesh.triangles.push_back({6, 6, 6});
  mesh.triangles.push_back({2, 6, 2});
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.triangles, 7u);
  EXPECT_EQ(s.degenerate_triangles, 5u);
  MeshStats expected = g2s::compute_stats(square());
  expected.triangles = 7;
  expected.degenerate_triangles = 5;
  EXPECT_EQ(all_fields(s), all_fields(expected));  // vertices stays 4, components 1
}

TEST(Stats, DegenerateTrianglesConnectNothing) {
  IndexedMesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  const IndexedMesh copy = mesh;
  append(mesh, copy, {5, 0, 0});
  mesh.triangles.push_back({0, 3, 3});
  mesh.triangles.push_back({0, 1, 4});  // collinear along the x axis
  const MeshStats s = g2s::compute_stats(mesh);
  EXPECT_EQ(s.degenerate_triangles, 2u);
  EXPECT_EQ(s.components, 2u);
  EXPECT_EQ(s.holes, 2u);
  EXPECT_EQ(s.vertices, 6u);
}

TEST(Stats, WeldingGivesTheIndexedAnswer) {
  for (const IndexedMesh& mesh : {tetrahedron(), octahedron(), square(),
                                  grid(5, 4, false, false, [](int i, int j) { return i == j; })}) {
    IndexedMesh soup = unweld(mesh);
    // Negative zeros must weld onto positive ones.
    for (double& c : soup.xyz) {
      if (c == 0.0 && (&c - soup.xyz.data()) % 2 == 0) c = -0.0;
    }
    EXPECT_EQ(all_fields(g2s::compute_stats(soup)), all_fields(g2s::compute_stats(mesh)));
  }
  // Two tetrahedra sharing a vertex: welding is what makes the vertex non-manifold.
  IndexedMesh two = tetrahedron();
  append(two, tetrahedron(), {0, 0, 1});
  const MeshStats soup = g2s::compute_stats(unweld(two));
  EXPECT_EQ(soup.non_manifold_vertices_type1, 1u);
  EXPECT_EQ(soup.vertices, 7u);
}

TEST(Stats, OrderDoesNotMatter) {
  IndexedMesh mesh =
      grid(30, 20, false, false, [](int i, int j) { return (i * 7 + j * 3) % 11 == 0; });
  mesh.triangles.push_back(mesh.triangles[5]);
  // Same orientation: with a reversed copy the first copy in input order is the one kept, and
  // orientation conflicts depend on which that is.
  mesh.triangles.push_back({mesh.triangles[9][1], mesh.triangles[9][2], mesh.triangles[9][0]});
  const std::string expected = all_fields(g2s::compute_stats(mesh));
  std::mt19937 rng(7);
  std::vector<Index> perm(mesh.vertex_count());
  std::iota(perm.begin(), perm.end(), Index{0});
  std::shuffle(perm.begin(), perm.end(), rng);
  IndexedMesh shuffled;
  shuffled.xyz.resize(mesh.xyz.size());
  for (std::size_t i = 0; i < perm.size(); ++i) {
    for (int k = 0; k < 3; ++k) shuffled.xyz[3 * std::size_t{perm[i]} + k] = mesh.xyz[3 * i + k];
  }
  for (Triangle t : mesh.triangles) {
    std::rotate(t.begin(), t.begin() + rng() % 3, t.end());
    shuffled.triangles.push_back({perm[t[0]], perm[t[1]], perm[t[2]]});
  }
  std::shuffle(shuffled.triangles.begin(), shuffled.triangles.end(), rng);
  EXPECT_EQ(all_fields(g2s::compute_stats(shuffled)), expected);
}

TEST(Stats, TorusAndCylinder) {
  const MeshStats torus = g2s::compute_stats(grid(40, 16, true, true));
  EXPECT_EQ(torus.triangles, 2u * 40 * 16);
  EXPECT_EQ(torus.vertices, 40u * 16);
  expect_clean(torus);
  EXPECT_EQ(torus.boundary_edges, 0u);
  EXPECT_EQ(torus.holes, 0u);
  EXPECT_EQ(torus.components, 1u);

  const MeshStats cylinder = g2s::compute_stats(grid(24, 10, true, false));
  expect_clean(cylinder);
  EXPECT_EQ(cylinder.boundary_edges, 2u * 24);
  EXPECT_EQ(cylinder.holes, 2u);  // one per rim
  EXPECT_EQ(cylinder.components, 1u);
}

// Coverage compares at float precision when every vertex lies on floats (an STL's do), so that an
// STL of a double cloud covers it, and exactly otherwise.
TEST(Stats, Coverage) {
  IndexedMesh mesh = tetrahedron();
  mesh.xyz[0] = static_cast<float>(0.1);  // vertex 0 at (0.1, 0, 0) as STL's float stores it
  g2s::PointCloud cloud;
  cloud.xyz = {0.1, -0.0, 0,   1, 0, 0, 0, 1, 0, 0, 0, 1,  // the four vertices, 0.1 as read
               1,   0,    0,                               // a duplicate point, counted twice
               0.5, 0.5,  0.5, 2, 2, 2};                   // not vertices
  const MeshStats s = g2s::compute_stats(mesh, &cloud);
  EXPECT_TRUE(s.has_coverage);
  EXPECT_EQ(s.input_points, 7u);
  EXPECT_EQ(s.covered_points, 5u);
  EXPECT_DOUBLE_EQ(s.coverage, 5.0 / 7);

  // A double mesh: 0.1 is covered, its float rounding is another point.
  mesh.xyz[0] = 0.1;
  cloud.xyz.insert(cloud.xyz.end(), {static_cast<float>(0.1), 0, 0});
  const MeshStats exact = g2s::compute_stats(mesh, &cloud);
  EXPECT_EQ(exact.input_points, 8u);
  EXPECT_EQ(exact.covered_points, 5u);

  // Georeferenced: float's step is half a metre at 5e6, and points 1 cm apart are not one.
  IndexedMesh far = tetrahedron();
  g2s::PointCloud near_far;
  for (std::size_t k = 0; k < far.xyz.size(); ++k) {
    far.xyz[k] = far.xyz[k] * 0.01 + (k % 3 == 1 ? 5123456.789 : 512345.678);
    near_far.xyz.push_back(far.xyz[k]);
  }
  for (std::size_t k = 0; k < 3; ++k) near_far.xyz.push_back(far.xyz[k] + 0.005);
  EXPECT_EQ(g2s::compute_stats(far, &near_far).covered_points, 4u);

  const g2s::PointCloud none;
  const MeshStats empty = g2s::compute_stats(mesh, &none);
  EXPECT_TRUE(empty.has_coverage);
  EXPECT_EQ(empty.input_points, 0u);
  EXPECT_EQ(empty.coverage, 0.0);
}

TEST(Stats, BadIndexThrows) {
  IndexedMesh mesh = square();
  mesh.triangles.push_back({0, 1, 4});
  try {
    g2s::compute_stats(mesh);
    FAIL() << "no error";
  } catch (const g2s::Error& e) {
    EXPECT_EQ(e.code(), g2s::Exit::bad_input);
    EXPECT_NE(std::string(e.what()).find("triangle 2"), std::string::npos) << e.what();
  }
}

TEST(Stats, JsonHasEveryKeyInOrder) {
  g2s::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 7, 7, 7};
  const MeshStats s = g2s::compute_stats(tetrahedron(), &cloud);
  const std::string json = g2s::stats_to_json(s);
  const char* keys[] = {"triangles",
                        "vertices",
                        "degenerate_triangles",
                        "duplicate_triangles",
                        "non_manifold_edges",
                        "non_manifold_vertices",
                        "non_manifold_vertices_type1",
                        "non_manifold_vertices_type2",
                        "boundary_edges",
                        "holes",
                        "orientation_conflicts",
                        "components",
                        "crossing_pairs",
                        "crossing_pairs_no_shared_vertex",
                        "crossing_triangles",
                        "input_points",
                        "covered_points",
                        "off_mesh_points",
                        "off_mesh_within_1_spacing",
                        "off_mesh_within_2_spacings",
                        "off_mesh_within_4_spacings",
                        "off_mesh_beyond_4_spacings",
                        "off_mesh_isolated",
                        "off_mesh_far_not_isolated",
                        "coverage",
                        "surface_coverage",
                        "spacing",
                        "off_mesh_distance_median",
                        "off_mesh_distance_p90",
                        "off_mesh_distance_p99",
                        "off_mesh_distance_max"};
  std::size_t last = 0;
  for (const char* key : keys) {
    const std::size_t at = json.find(std::string("\"") + key + "\":");
    ASSERT_NE(at, std::string::npos) << key << " missing in " << json;
    EXPECT_GT(at, last) << key << " out of order in " << json;
    last = at;
  }
  EXPECT_EQ(json.front(), '{');
  EXPECT_EQ(json.back(), '}');
  EXPECT_NE(json.find("\"triangles\": 4,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"coverage\": 0.5,\n"), std::string::npos) << json;

  const std::string plain = g2s::stats_to_json(g2s::compute_stats(tetrahedron()));
  EXPECT_EQ(plain.find("coverage"), std::string::npos);
  EXPECT_EQ(plain.find("input_points"), std::string::npos);
  EXPECT_NE(plain.find("\"crossing_triangles\": 0\n}"), std::string::npos) << plain;
}

TEST(Stats, TextIsAligned) {
  g2s::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 7, 7, 7};
  const std::string text = g2s::stats_to_text(g2s::compute_stats(tetrahedron(), &cloud));
  EXPECT_NE(text.find("holes"), std::string::npos);
  EXPECT_NE(text.find("50.000%"), std::string::npos) << text;
  std::size_t width = 0;
  std::size_t start = 0;
  int lines = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    ASSERT_NE(end, std::string::npos);
    if (width == 0) width = end - start;
    EXPECT_EQ(end - start, width) << text;  // values end in one column
    start = end + 1;
    ++lines;
  }
  EXPECT_EQ(lines, 31);
}

// The command line: `g2s stats` on an ASCII STL written here (STL is a triangle soup, so this
// also checks welding through the reader).
class StatsCli : public g2s::test_support::FolderTest {
 protected:
  std::filesystem::path write_tetrahedron_stl() {
    const IndexedMesh mesh = tetrahedron();
    const auto path = dir_ / "tet.stl";
    std::ofstream out(path);
    out << "solid tet\n";
    for (const Triangle& t : mesh.triangles) {
      out << " facet normal 0 0 0\n  outer loop\n";
      for (const Index v : t) {
        out << "   vertex " << mesh.xyz[3 * v] << ' ' << mesh.xyz[3 * v + 1] << ' '
            << mesh.xyz[3 * v + 2] << '\n';
      }
      out << "  endloop\n endfacet\n";
    }
    out << "endsolid tet\n";
    return path;
  }

  g2s::test_support::CliRun run(const std::vector<std::string>& args) const {
    return g2s::test_support::run_cli(dir_, args);
  }
};

TEST_F(StatsCli, JsonOnStl) {
  const auto stl = write_tetrahedron_stl();
  const auto xyz = dir_ / "cloud.xyz";
  std::ofstream(xyz) << "0 0 0\n1 0 0\n5 5 5\n0 1 0\n";
  const g2s::test_support::CliRun r =
      run({"stats", stl.string(), "--json", "--points", xyz.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string& output = r.out;
  EXPECT_NE(output.find("\"triangles\": 4,"), std::string::npos) << output;
  EXPECT_NE(output.find("\"vertices\": 4,"), std::string::npos) << output;
  EXPECT_NE(output.find("\"holes\": 0,"), std::string::npos) << output;
  EXPECT_NE(output.find("\"covered_points\": 3,"), std::string::npos) << output;
  EXPECT_NE(output.find("\"coverage\": 0.75"), std::string::npos) << output;
}

TEST_F(StatsCli, TextAndErrors) {
  const auto stl = write_tetrahedron_stl();
  const g2s::test_support::CliRun text = run({"stats", stl.string()});
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("components"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find('{'), std::string::npos) << text.out;
  const g2s::test_support::CliRun missing = run({"stats", (dir_ / "missing.stl").string()});
  EXPECT_EQ(missing.code, 3) << missing.err;
  const g2s::test_support::CliRun no_mesh = run({"stats"});
  EXPECT_EQ(no_mesh.code, 2) << no_mesh.err;
}

}  // namespace
