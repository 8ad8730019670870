// The real LAS files of $G2S_DATA_DIR/las (PDAL's test suite, written by PDAL, Global Mapper and
// TerraScan) through the real `g2s mesh`: each meshes clean (no non-manifold edge or vertex, no
// orientation conflict, no duplicate or degenerate triangle), and autzen_trim.las gives the mesh
// of open-autzen-lidar.ply, which holds the same points shifted and rounded to float.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;

using g2s::test_support::data_dir;
using g2s::test_support::json_number;

class LasMesh : public ::testing::Test {
 protected:
  // `g2s mesh input -o dir/output --json`; returns stdout, fails the test on a non-zero exit.
  std::string mesh(const fs::path& input, const std::string& output) {
    const g2s::test_support::CliRun r = g2s::test_support::run_cli(
        folder_.path(), {"mesh", input.string(), "-o", output, "--json"});
    EXPECT_EQ(r.code, 0) << input << "\n" << r.err;
    return r.out;
  }
  g2s::test_support::TempFolder folder_{"g2s-las-mesh"};
};

TEST_F(LasMesh, EveryRealLasFileMeshesClean) {
  const char* const names[] = {"autzen_trim.las", "test1_4.las", "extrabytes.las", "4_6_crop.las",
                               "simple.las"};
  for (const char* name : names) G2S_SKIP_WITHOUT_DATA(data_dir() / "las" / name);
  for (const char* name : names) {
    SCOPED_TRACE(name);
    const fs::path path = data_dir() / "las" / name;
    const std::string json = mesh(path, "mesh.ply");
    std::printf("%s: %s\n", name, json.c_str());
    EXPECT_GT(json_number(json, "triangles"), json_number(json, "points"));
    for (const char* defect :
         {"non_manifold_edges", "non_manifold_vertices", "orientation_conflicts",
          "duplicate_triangles", "degenerate_triangles"}) {
      EXPECT_EQ(json_number(json, defect), 0.0) << defect;
    }
  }
}

TEST_F(LasMesh, AutzenLasAndPlyGiveTheSameMesh) {
  const fs::path las = data_dir() / "las" / "autzen_trim.las";
  const fs::path ply = data_dir() / "open-autzen-lidar.ply";
  G2S_SKIP_WITHOUT_DATA(las);
  G2S_SKIP_WITHOUT_DATA(ply);
  const std::string a = mesh(las, "las.ply");
  const std::string b = mesh(ply, "ply.ply");
  EXPECT_EQ(json_number(a, "points"), json_number(b, "points"));
  const double ta = json_number(a, "triangles");
  const double tb = json_number(b, "triangles");
  EXPECT_LE(std::abs(ta - tb), 0.001 * tb) << ta << " vs " << tb;
  for (const char* defect : {"non_manifold_edges", "non_manifold_vertices", "orientation_conflicts",
                             "duplicate_triangles", "degenerate_triangles"}) {
    EXPECT_EQ(json_number(a, defect), json_number(b, defect)) << defect;
  }
  // Boundary edges, holes and components follow the triangles: ties broken differently by the float
  // rounding may open or close a few, and a hole filled or not changes the count by one. Growth
  // is a chain of choices: moving the search radius cap by 0.5% moves autzen's holes over
  // 194-210 (its boundary edges over 9,022-9,373), so the two roundings may differ by as much.
  const double ba = json_number(a, "boundary_edges");
  const double bb = json_number(b, "boundary_edges");
  EXPECT_LE(std::abs(ba - bb), 0.02 * bb) << ba << " vs " << bb;
  EXPECT_LE(std::abs(json_number(a, "holes") - json_number(b, "holes")),
            0.1 * json_number(b, "holes") + 2);
  // Small pieces at the scan's ragged edges come and go with the float rounding of either file.
  EXPECT_LE(std::abs(json_number(a, "components") - json_number(b, "components")),
            0.1 * json_number(b, "components") + 2);
  std::printf(
      "autzen LAS: %.0f triangles, %.0f boundary edges, %.0f holes, %.0f components\n"
      "autzen PLY: %.0f triangles, %.0f boundary edges, %.0f holes, %.0f components\n",
      ta, ba, json_number(a, "holes"), json_number(a, "components"), tb, bb,
      json_number(b, "holes"), json_number(b, "components"));
}

}  // namespace
