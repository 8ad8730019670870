// `g2s mesh` gives the same bytes for any --threads, whatever --memory plans: the tile size comes
// from the budget alone (the threads only change how many tiles are in flight). Checked on a real
// scan and on a synthetic cloud cut into many tiles, at budgets where the plan of an earlier
// version cut the cloud differently for each thread count.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

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
  expect_same_bytes(cloud, {"48M", "64M"}, 8);
}

}  // namespace
