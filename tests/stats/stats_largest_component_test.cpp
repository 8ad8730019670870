// Tests of largest_component (include/g2s/stats.hpp) and `g2s stats --largest-component`: a
// scan's surface measured apart from stray patches (docs/robustness.md, outliers).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/stats.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

// A closed tetrahedron (vertices 0-3), a lone triangle (4-6) listed before it, and a strip of two
// triangles (7-10) sharing an edge.
g2s::IndexedMesh three_pieces() {
  g2s::IndexedMesh mesh;
  mesh.xyz = {1, 1, 1, 1,  -1, -1, -1, 1, -1, -1, -1, 1,   // tetrahedron
              5, 0, 0, 6,  0,  0,  5,  1, 0,               // lone triangle
              9, 0, 0, 10, 0,  0,  10, 1, 0,  9,  1,  0};  // strip
  mesh.triangles = {{4, 5, 6}, {0, 1, 2}, {7, 8, 9}, {0, 3, 1}, {0, 2, 3}, {7, 9, 10}, {1, 3, 2}};
  return mesh;
}

TEST(LargestComponent, KeepsTheBiggestPieceInInputOrder) {
  const g2s::IndexedMesh mesh = three_pieces();
  EXPECT_EQ(g2s::compute_stats(mesh).components, 3u);
  const g2s::IndexedMesh largest = g2s::largest_component(mesh);
  EXPECT_EQ(largest.xyz, mesh.xyz);
  const std::vector<g2s::Triangle> expected{{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  EXPECT_EQ(largest.triangles, expected);
  const g2s::MeshStats s = g2s::compute_stats(largest);
  EXPECT_EQ(s.components, 1u);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.holes, 0u);
}

TEST(LargestComponent, TiesGoToTheFirstPieceAndEmptyStaysEmpty) {
  g2s::IndexedMesh mesh = three_pieces();
  // Two pieces of two triangles: the strip starts first, though the other one is complete first.
  mesh.triangles = {{7, 8, 9}, {0, 1, 2}, {0, 3, 1}, {4, 5, 6}, {7, 9, 10}};
  const std::vector<g2s::Triangle> strip{{7, 8, 9}, {7, 9, 10}};
  EXPECT_EQ(g2s::largest_component(mesh).triangles, strip);
  mesh.triangles.clear();
  EXPECT_TRUE(g2s::largest_component(mesh).triangles.empty());
  mesh.triangles = {{0, 1, 11}};
  EXPECT_THROW(g2s::largest_component(mesh), g2s::Error);
}

TEST(LargestComponent, CommandLine) {
  const g2s::test_support::TempFolder folder("g2s-largest-cli");
  const std::filesystem::path& dir = folder.path();
  const g2s::IndexedMesh mesh = three_pieces();
  g2s::write_mesh(dir / "pieces.ply", mesh.xyz, mesh.triangles, g2s::MeshFormat::ply_binary);
  const g2s::test_support::CliRun run = g2s::test_support::run_cli(
      dir, {"stats", (dir / "pieces.ply").string(), "--largest-component", "--json"});
  ASSERT_EQ(run.code, 0) << run.err;
  const std::string& json = run.out;
  EXPECT_NE(json.find("\"triangles\": 4,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"components\": 1"), std::string::npos) << json;
}

}  // namespace
