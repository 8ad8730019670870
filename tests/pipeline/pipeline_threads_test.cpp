// `g2s mesh` gives the same bytes for any --threads, whatever --memory plans: the tile size comes
// from the budget alone (the threads only change how many tiles are in flight). Checked on a real
// scan and on a synthetic cloud cut into many tiles, at budgets where the plan of an earlier
// version cut the cloud differently for each thread count.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "g2s/pipeline.hpp"
#include "g2s/synth.hpp"
#include "g2s/tile_store.hpp"
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
    const std::string command = fmt::format(
        "\"{}\" mesh \"{}\" -o \"{}\" --keep-store \"{}\" --memory {} --threads {} -q "
        "--no-stats",
        G2S_CLI_PATH, cloud.string(), out.string(), store.string(), memory, threads);
    const int status = std::system(command.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
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
  const char* env = std::getenv("G2S_DATA_DIR");
  const fs::path data = env && *env ? fs::path(env) : fs::path(G2S_DEFAULT_DATA_DIR);
  const fs::path cloud = data / "raw-bunny.ply";
  if (!fs::exists(cloud)) GTEST_SKIP() << "no " << cloud << " (set G2S_DATA_DIR)";
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
