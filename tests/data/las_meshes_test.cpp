// The real LAS files of $G2S_DATA_DIR/las (PDAL's test suite, written by PDAL, Global Mapper and
// TerraScan) through the real `g2s mesh`: each meshes clean (no non-manifold edge or vertex, no
// orientation conflict, no duplicate or degenerate triangle), and autzen_trim.las gives the mesh
// of open-autzen-lidar.ply, which holds the same points shifted and rounded to float.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;

fs::path data_dir() {
  const char* env = std::getenv("G2S_DATA_DIR");
  return env && *env ? fs::path(env) : fs::path(G2S_DEFAULT_DATA_DIR);
}

// The number after "key": (or "key": ) in a JSON text.
double json_number(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  if (at == std::string::npos) {
    ADD_FAILURE() << "no " << key << " in " << json;
    return std::numeric_limits<double>::quiet_NaN();
  }
  return std::strtod(json.c_str() + at + key.size() + 3, nullptr);
}

class LasMesh : public ::testing::Test {
 protected:
  // `g2s mesh input -o dir/output --json`; returns stdout, fails the test on a non-zero exit.
  std::string mesh(const fs::path& input, const std::string& output) {
    const fs::path out = folder_.path() / "stdout.txt";
    const fs::path err = folder_.path() / "stderr.txt";
    const std::string command = std::string("\"") + G2S_CLI_PATH + "\" mesh \"" + input.string() +
                                "\" -o \"" + (folder_.path() / output).string() + "\" --json > \"" +
                                out.string() + "\" 2> \"" + err.string() + "\"";
    const int status = std::system(command.c_str());
    std::ifstream o(out), e(err);
    const std::string json{std::istreambuf_iterator<char>(o), std::istreambuf_iterator<char>()};
    const std::string errors{std::istreambuf_iterator<char>(e), std::istreambuf_iterator<char>()};
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command << "\n" << errors;
    return json;
  }
  g2s::test_support::TempFolder folder_{"g2s-las-mesh"};
};

TEST_F(LasMesh, EveryRealLasFileMeshesClean) {
  for (const char* name :
       {"autzen_trim.las", "test1_4.las", "extrabytes.las", "4_6_crop.las", "simple.las"}) {
    SCOPED_TRACE(name);
    const fs::path path = data_dir() / "las" / name;
    if (!fs::exists(path)) GTEST_SKIP() << "no " << path << " (set G2S_DATA_DIR)";
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
  if (!fs::exists(las) || !fs::exists(ply)) GTEST_SKIP() << "no autzen files (set G2S_DATA_DIR)";
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
  // rounding may open or close a few, and a hole filled or not changes the count by one.
  const double ba = json_number(a, "boundary_edges");
  const double bb = json_number(b, "boundary_edges");
  EXPECT_LE(std::abs(ba - bb), 0.01 * bb) << ba << " vs " << bb;
  EXPECT_LE(std::abs(json_number(a, "holes") - json_number(b, "holes")),
            0.05 * json_number(b, "holes") + 2);
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
