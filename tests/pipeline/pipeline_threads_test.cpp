// `g2s mesh` gives the same bytes for any --threads, whatever --memory plans: the tile size comes
// from the budget alone (the threads only change how many tiles are in flight). Checked on a real
// scan and on a synthetic cloud cut into many tiles, at budgets where the plan of an earlier
// version cut the cloud differently for each thread count. And the pipeline runs in an arena of
// the threads asked for.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <array>
#include <filesystem>
#include <span>
#include <string>

#include "g2s/mesh_sink.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/synth.hpp"
#include "g2s/tile_store.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;

class ThreadCount : public ::testing::Test {
 protected:
  // Meshes `cloud` with the CLI; returns the output's bytes and, in `tiles`, the tile count.
  std::string mesh(const fs::path& cloud, const std::string& memory, int threads,
                   std::size_t* tiles) const {
    const fs::path out = dir_ / fmt::format("t{}.stl", threads);
    const fs::path store = dir_ / fmt::format("t{}.store", threads);
    const g2s::test_support::CliRun r = g2s::test_support::run_cli(
        dir_, {"mesh", cloud.string(), "-o", out.string(), "--keep-store", store.string(),
               "--memory", memory, "--threads", std::to_string(threads), "-q", "--no-stats"});
    EXPECT_EQ(r.code, 0) << r.err;
    *tiles = g2s::TileStore(store).tiles().size();
    fs::remove(store);
    return g2s::test_support::file_bytes(out);
  }

  // 1, 2, 3 and 4 threads at each budget: the same tiles and the same bytes.
  void expect_same_bytes(const fs::path& cloud, std::initializer_list<const char*> budgets,
                         std::size_t fewest_tiles) const {
    for (const char* memory : budgets) {
      std::size_t tiles_one = 0;
      const std::string one = mesh(cloud, memory, 1, &tiles_one);
      EXPECT_GE(tiles_one, fewest_tiles) << "--memory " << memory;
      ASSERT_GT(one.size(), 84u);
      for (int threads = 2; threads <= 4; ++threads) {
        std::size_t tiles = 0;
        const std::string other = mesh(cloud, memory, threads, &tiles);
        EXPECT_EQ(tiles, tiles_one) << "--memory " << memory << ", " << threads << " threads";
        EXPECT_TRUE(other == one) << "--memory " << memory << ": " << threads
                                  << " threads differ from 1";
      }
    }
  }

  g2s::test_support::TempFolder folder_{"g2s-threads"};
  const fs::path dir_ = folder_.path();
};

TEST_F(ThreadCount, SameBytesOnARealScanAtSeveralBudgets) {
  const fs::path cloud = g2s::test_support::data_dir() / "raw-bunny.ply";
  G2S_SKIP_WITHOUT_DATA(cloud);
  expect_same_bytes(cloud, {"64M", "100M"}, 8);
}

TEST_F(ThreadCount, SameBytesOnACloudOfManyTiles) {
  g2s::SynthOptions o;
  o.shape = g2s::SynthShape::torus;
  o.points = 120000;
  o.noise = 0.1;
  const fs::path cloud = dir_ / "torus.ply";
  g2s::write_synthetic_cloud(cloud.string(), o);
  expect_same_bytes(cloud, {"36M", "48M"}, 8);
}

// The tiles grow and stitch in an arena of options.threads threads: the caller's own when it has
// that size (g2s mesh runs every stage in one), a new one otherwise.
class ArenaSink final : public g2s::MeshSink {
 public:
  void vertex(g2s::Index, const double*) override {}
  void triangle(const g2s::Triangle&, const std::array<const double*, 3>&, std::uint32_t) override {
    concurrency = tbb::this_task_arena::max_concurrency();
    ++triangles;
  }
  void finish(std::span<const std::uint8_t>) override {}
  int concurrency = 0;
  std::size_t triangles = 0;
};

TEST(MeshTiles, RunsInAnArenaOfTheThreadsAskedFor) {
  g2s::SynthOptions o;
  o.shape = g2s::SynthShape::torus;
  o.points = 20000;
  const g2s::PointCloud cloud = g2s::make_synthetic_cloud(o);
  const g2s::MemoryTiles tiles(cloud, 4000);
  const auto concurrency_in = [&](int caller, int threads) {
    g2s::PipelineOptions options;
    options.threads = threads;
    ArenaSink sink;
    tbb::task_arena(caller).execute([&] { g2s::mesh_tiles(tiles, options, sink); });
    EXPECT_GT(sink.triangles, 30000u);
    return sink.concurrency;
  };
  EXPECT_EQ(concurrency_in(3, 3), 3);
  EXPECT_EQ(concurrency_in(3, 1), 1);
  EXPECT_EQ(concurrency_in(1, 2), 2);
}

}  // namespace
