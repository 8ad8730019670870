// The pipeline's stages as separate processes (g2s tile, grow, stitch), as GNU parallel runs
// them, give the same bytes as g2s mesh, with any thread count; growth files refuse to be
// stitched when truncated, corrupt or from another store; each triangle is kept by one tile
// only; seams placed through sharp edges, a thin plate and a hole close cleanly.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/stats.hpp"
#include "g2s/synth.hpp"
#include "g2s/tile_stages.hpp"
#include "g2s/tile_store.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;
using g2s::test_support::file_bytes;

class Stages : public ::testing::Test {
 protected:
  void SetUp() override {
    g2s::SynthOptions o;
    o.shape = g2s::SynthShape::torus;
    o.points = 30000;
    o.noise = 0.2;
    cloud_ = (dir_ / "torus.ply").string();
    g2s::write_synthetic_cloud(cloud_, o);
  }

  // Runs the CLI in the test folder; returns its exit code, stderr in `err`.
  int run(const std::vector<std::string>& args, std::string* err = nullptr) const {
    const g2s::test_support::CliRun r = g2s::test_support::run_cli(dir_, args);
    if (err) *err = r.err;
    return r.code;
  }

  g2s::test_support::TempFolder folder_{"g2s-stages"};
  const fs::path dir_ = folder_.path();
  std::string cloud_;
};

TEST_F(Stages, SeparateProcessesGiveTheBytesOfOneMeshRunForAnyThreadCount) {
  ASSERT_EQ(
      run({"mesh", "torus.ply", "-o", "one.stl", "--tile-points", "2000", "--threads", "1", "-q"}),
      0);
  ASSERT_EQ(
      run({"mesh", "torus.ply", "-o", "two.stl", "--tile-points", "2000", "--threads", "2", "-q"}),
      0);
  ASSERT_EQ(run({"tile", "torus.ply", "s.store", "--tile-points", "2000", "-q"}), 0);
  const g2s::TileStore store(dir_ / "s.store");
  const std::size_t tiles = store.tiles().size();
  ASSERT_GE(tiles, 10u);
  const std::size_t half = tiles / 2;
  ASSERT_EQ(
      run({"grow", "s.store", "--tiles", fmt::format("0-{}", half - 1), "--threads", "1", "-q"}),
      0);
  ASSERT_EQ(run({"grow", "s.store", "--tiles", fmt::format("{}-{}", half, tiles - 1), "-q"}), 0);
  ASSERT_EQ(run({"stitch", "s.store", "-o", "staged.stl", "-q"}), 0);
  const std::string one = file_bytes(dir_ / "one.stl");
  ASSERT_GT(one.size(), 84u);
  EXPECT_TRUE(one == file_bytes(dir_ / "two.stl")) << "1 and 2 threads differ";
  EXPECT_TRUE(one == file_bytes(dir_ / "staged.stl")) << "separate stages differ from g2s mesh";
  // A range that runs backwards, or past the store's tiles, is refused saying which.
  std::string err;
  EXPECT_EQ(run({"grow", "s.store", "--tiles", "5-2"}, &err), 2);
  EXPECT_NE(err.find("runs backwards"), std::string::npos) << err;
  EXPECT_EQ(run({"grow", "s.store", "--tiles", fmt::format("0-{}", tiles)}, &err), 2);
  EXPECT_NE(err.find(fmt::format("the store has tiles 0-{}", tiles - 1)), std::string::npos) << err;
  // Growing again finds every tile done: nothing changes.
  ASSERT_EQ(run({"grow", "s.store"}, &err), 0);
  EXPECT_NE(err.find("(" + std::to_string(tiles) + " already there)"), std::string::npos) << err;
}

// tile-info shows each tile's halo, as count_halo_points counts it, so that a tile-by-tile
// pipeline can size a machine by what a tile grows with.
TEST_F(Stages, TileInfoShowsEachTilesHalo) {
  ASSERT_EQ(run({"tile", "torus.ply", "s.store", "--tile-points", "2000", "-q"}), 0);
  const g2s::test_support::CliRun info =
      g2s::test_support::run_cli(dir_, {"tile-info", "s.store", "--json"});
  ASSERT_EQ(info.code, 0) << info.err;
  const g2s::TileStore store(dir_ / "s.store");
  const std::vector<std::uint64_t> halo = g2s::count_halo_points(store, {});
  ASSERT_GE(halo.size(), 10u);
  std::size_t at = 0;
  for (std::size_t t = 0; t < halo.size(); ++t) {
    at = info.out.find("\"halo_points\":", at);
    ASSERT_NE(at, std::string::npos) << "tile " << t;
    EXPECT_EQ(std::strtoull(info.out.c_str() + at + 14, nullptr, 10), halo[t]) << "tile " << t;
    EXPECT_GT(halo[t], 0u);
    ++at;
  }
  const std::string text = g2s::test_support::cli_output(dir_, {"tile-info", "s.store"}, 0);
  EXPECT_NE(text.find("halo"), std::string::npos);
}

TEST_F(Stages, GnuParallelDrivesTheGrowStage) {
  if (std::system("command -v parallel > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "GNU parallel is not installed (scripts/install-deps.sh installs it)";
  }
  ASSERT_EQ(run({"mesh", "torus.ply", "-o", "one.stl", "--tile-points", "2000", "-q"}), 0);
  ASSERT_EQ(run({"tile", "torus.ply", "s.store", "--tile-points", "2000", "-q"}), 0);
  const std::size_t tiles = g2s::TileStore(dir_ / "s.store").tiles().size();
  // One job per tile, up to 4 at once, exactly as docs/pipeline.md shows.
  const std::string command = "cd \"" + dir_.string() + "\" && seq 0 " + std::to_string(tiles - 1) +
                              " | parallel -j4 --halt now,fail=1 \"" + G2S_CLI_PATH +
                              "\" grow s.store --tiles {} --threads 1 -q";
  ASSERT_EQ(std::system(command.c_str()), 0);
  ASSERT_EQ(run({"stitch", "s.store", "-o", "parallel.stl", "-q"}), 0);
  EXPECT_TRUE(file_bytes(dir_ / "one.stl") == file_bytes(dir_ / "parallel.stl"))
      << "GNU parallel stages differ from g2s mesh";
}

TEST_F(Stages, StitchRefusesMissingCorruptTruncatedOrForeignGrowths) {
  ASSERT_EQ(run({"tile", "torus.ply", "s.store", "--tile-points", "4000", "-q"}), 0);
  std::string err;
  EXPECT_EQ(run({"stitch", "s.store", "-o", "out.stl"}, &err), 3);
  EXPECT_NE(err.find("was the tile grown"), std::string::npos) << err;
  ASSERT_EQ(run({"grow", "s.store", "-q"}), 0);
  const fs::path growth = dir_ / "s.store.grown" / "tile-000001.g2sgrow";
  const std::string good = file_bytes(growth);
  auto write = [&](const std::string& bytes) {
    std::ofstream(growth, std::ios::binary | std::ios::trunc) << bytes;
  };
  std::string bad = good;
  bad[bad.size() / 2] ^= 0x10;
  write(bad);
  EXPECT_EQ(run({"stitch", "s.store", "-o", "out.stl"}, &err), 3);
  EXPECT_NE(err.find("triangle checksum mismatch"), std::string::npos) << err;
  bad = good;
  bad[20] ^= 0x01;  // inside the header
  write(bad);
  EXPECT_EQ(run({"stitch", "s.store", "-o", "out.stl"}, &err), 3);
  EXPECT_NE(err.find("header checksum mismatch"), std::string::npos) << err;
  write(good.substr(0, good.size() - 7));
  EXPECT_EQ(run({"stitch", "s.store", "-o", "out.stl"}, &err), 3);
  EXPECT_NE(err.find("truncated"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "out.stl"));
  // Growths of another store (other tiles) are refused, and the grow stage redoes them.
  write(good);
  ASSERT_EQ(run({"tile", "torus.ply", "other.store", "--tile-points", "3000", "-q"}), 0);
  EXPECT_EQ(run({"stitch", "other.store", "--grown", "s.store.grown", "-o", "out.stl"}, &err), 3);
  EXPECT_NE(err.find("different tile store"), std::string::npos) << err;
  write(good.substr(0, 50));
  ASSERT_EQ(run({"grow", "s.store"}, &err), 0);
  EXPECT_TRUE(file_bytes(growth) == good) << "a tile grown again gives other bytes";
}

// Tile growths: every kept triangle has all its corners in its own tile, so no triangle is kept
// by two tiles, and nothing is lost: with the seams stitched the torus is closed.
TEST(PipelineOwnership, EachTriangleIsKeptByOneTileOnly) {
  g2s::SynthOptions o;
  o.shape = g2s::SynthShape::torus;
  o.points = 20000;
  const g2s::PointCloud cloud = g2s::make_synthetic_cloud(o);
  const g2s::MemoryTiles tiles(cloud, 1500);
  ASSERT_GE(tiles.tiles().size(), 16u);
  std::vector<std::size_t> tile_of(cloud.size());
  for (std::size_t t = 0; t < tiles.tiles().size(); ++t) {
    for (g2s::Index id : tiles.load(t).ids) tile_of[id] = t;
  }
  std::set<std::array<g2s::Index, 3>> seen;
  for (std::size_t t = 0; t < tiles.tiles().size(); ++t) {
    const g2s::TileGrowth g = g2s::grow_tile(tiles, t, {});
    EXPECT_GT(g.triangles.size(), 0u);
    const std::vector<g2s::Index> ids = tiles.load(t).ids;  // corners index the tile's points
    for (g2s::Triangle tri : g.triangles) {
      for (g2s::Index& v : tri) {
        ASSERT_LT(v, ids.size());
        v = ids[v];
        ASSERT_EQ(tile_of[v], t);
      }
      std::sort(tri.begin(), tri.end());
      EXPECT_TRUE(seen.insert(tri).second);
    }
  }
}

// A seam placed on purpose: the cloud cut by one plane into two tiles.
g2s::MeshStats mesh_with_cut(const g2s::PointCloud& cloud, int axis, double at) {
  g2s::TileBox all;
  for (int a = 0; a < 3; ++a) {
    all.lo[a] = all.hi[a] = cloud.xyz[a];
  }
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      all.lo[a] = std::min(all.lo[a], cloud.xyz[3 * i + a]);
      all.hi[a] = std::max(all.hi[a], cloud.xyz[3 * i + a]);
    }
  }
  g2s::TileBox low = all, high = all;
  low.hi[axis] = at;
  high.lo[axis] = at;
  const g2s::MemoryTiles tiles(cloud, std::vector<g2s::TileBox>{low, high});
  const g2s::PipelineMesh mesh = g2s::mesh_tiles(tiles, {});
  return g2s::compute_stats(g2s::IndexedMesh{cloud.xyz, mesh.triangles}, &cloud);
}

void expect_seam_closes(const g2s::PointCloud& cloud, int axis, double at) {
  const g2s::MemoryTiles one(cloud, cloud.size());
  const g2s::PipelineMesh single = g2s::mesh_tiles(one, {});
  const g2s::MeshStats s1 = g2s::compute_stats(g2s::IndexedMesh{cloud.xyz, single.triangles});
  const g2s::MeshStats s = mesh_with_cut(cloud, axis, at);
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_EQ(s.non_manifold_vertices, 0u);
  EXPECT_EQ(s.orientation_conflicts, 0u);
  EXPECT_EQ(s.duplicate_triangles, 0u);
  EXPECT_LE(static_cast<double>(s.boundary_edges),
            static_cast<double>(s1.boundary_edges) * 1.02 + 6)
      << "seam at axis " << axis << " = " << at;
  EXPECT_LE(s.holes, s1.holes + 1);
}

TEST(PipelineSeams, ThroughTheSharpEdgesOfACube) {
  g2s::SynthOptions o;
  o.shape = g2s::SynthShape::cube;  // edge 2, centred at the origin
  o.points = 30000;
  const g2s::PointCloud cloud = g2s::make_synthetic_cloud(o);
  expect_seam_closes(cloud, 0, 0.999);  // a hair inside the face x = 1: along its sharp edges
  expect_seam_closes(cloud, 2, 0.0);    // across four faces
}

TEST(PipelineSeams, ThroughAThinPlate) {
  g2s::SynthOptions o;
  o.shape = g2s::SynthShape::plate;  // 2 x 2 x 0.05, closed
  // Sheets 3.6 and 2 spacings apart: in the second, each sheet is within the reach of the
  // stitcher's orientation vote (3 spacings) of the other and must not vote it to face its way.
  for (const int points : {30000, 9000}) {
    o.points = points;
    const g2s::PointCloud cloud = g2s::make_synthetic_cloud(o);
    expect_seam_closes(cloud, 2, 0.0);  // between the two sheets, parallel to them
    expect_seam_closes(cloud, 0, 0.1);  // across both sheets and the thin rim
  }
}

TEST(PipelineSeams, ThroughAHole) {
  g2s::SynthOptions o;
  o.shape = g2s::SynthShape::sphere;
  o.points = 30000;
  g2s::PointCloud sphere = g2s::make_synthetic_cloud(o);
  g2s::PointCloud holed;  // a round hole of radius 0.3 around the +x pole
  for (std::size_t i = 0; i < sphere.size(); ++i) {
    const double* p = &sphere.xyz[3 * i];
    if (p[0] > 0 && std::hypot(p[1], p[2]) < 0.3) continue;
    holed.xyz.insert(holed.xyz.end(), p, p + 3);
  }
  expect_seam_closes(holed, 1, 0.0);  // the seam crosses the hole
}

}  // namespace
