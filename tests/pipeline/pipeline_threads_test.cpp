// `g2s mesh` gives the same bytes for any --threads, whatever --memory plans: the tile size comes
// from the budget alone (the threads only change how many tiles are in flight). Checked on a real
// scan and on a synthetic cloud cut into many tiles, at budgets where the plan of an earlier
// version cut the cloud differently for each thread count. And the pipeline runs in an arena of
// the threads asked for, stitches in tile order with at most tiles_in_flight tiles begun and not
// yet stitched (large ones early), and passes on a tile's failure.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "g2s/error.hpp"
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

// A synthetic cloud of `points` points on `shape`.
g2s::PointCloud synthetic(g2s::SynthShape shape, std::uint64_t points, double noise = 0) {
  g2s::SynthOptions o;
  o.shape = shape;
  o.points = points;
  o.noise = noise;
  return g2s::make_synthetic_cloud(o);
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
  const g2s::PointCloud cloud = synthetic(g2s::SynthShape::torus, 20000);
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

// A TileSource over another that counts the tiles whose growth has begun (their load()) against
// those stitched (told by the pipeline's progress), and fails to load one tile.
class CountingTiles final : public g2s::TileSource {
 public:
  explicit CountingTiles(const g2s::TileSource& inner,
                         std::size_t failing = std::numeric_limits<std::size_t>::max(),
                         bool hold_first = false)
      : inner_(inner), failing_(failing), hold_first_(hold_first) {}
  std::span<const g2s::TileInfo> tiles() const override { return inner_.tiles(); }
  double cloud_spacing() const override { return inner_.cloud_spacing(); }
  double group_distance() const override { return inner_.group_distance(); }
  double twin_distance() const override { return inner_.twin_distance(); }
  g2s::TilePoints load(std::size_t tile) const override {
    if (tile == failing_) throw g2s::Error(g2s::Exit::bad_input, "tile cannot be read");
    const std::size_t begun = ++begun_;
    const std::size_t ahead = begun - stitched_;
    if (begun <= 2) first_two_[begun - 1] = tile;
    // The first tile's growth waits (up to 10 s) until another thread has begun a tile.
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (hold_first_ && begun == 1 && begun_ < 2 && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::yield();
    }
    for (std::size_t most = most_ahead_;
         ahead > most && !most_ahead_.compare_exchange_weak(most, ahead);) {
    }
    return inner_.load(tile);
  }
  g2s::TilePoints load_border(std::size_t tile, double distance) const override {
    return inner_.load_border(tile, distance);
  }
  // The pipeline's progress: tiles stitched so far; false when not the next in order.
  bool stitched(std::uint64_t done) {
    const bool in_order = done == stitched_ + 1;
    stitched_ = done;
    return in_order;
  }
  std::size_t most_ahead() const { return most_ahead_; }
  // The first two tiles whose growth began, the smaller first (two threads may load them in
  // either order).
  std::pair<std::size_t, std::size_t> first_two_begun() const {
    return std::minmax(first_two_[0].load(), first_two_[1].load());
  }

 private:
  const g2s::TileSource& inner_;
  const std::size_t failing_;
  const bool hold_first_;
  mutable std::atomic<std::size_t> begun_{0}, stitched_{0}, most_ahead_{0};
  mutable std::array<std::atomic<std::size_t>, 2> first_two_{};
};

TEST(MeshTiles, StitchesInOrderWithAtMostTheTilesInFlight) {
  const g2s::PointCloud cloud = synthetic(g2s::SynthShape::torus, 20000, 0.1);
  const g2s::MemoryTiles tiles(cloud, 1500);
  ASSERT_GE(tiles.tiles().size(), 12u);
  const g2s::PipelineMesh one = g2s::mesh_tiles(tiles, {});
  ASSERT_GT(one.triangles.size(), 30000u);
  for (const std::size_t in_flight : {1, 2, 5}) {
    for (int threads = 1; threads <= 4; ++threads) {
      CountingTiles counting(tiles);
      g2s::PipelineOptions options;
      options.threads = threads;
      options.tiles_in_flight = in_flight;
      bool in_order = true;
      options.progress = [&](std::uint64_t done, std::uint64_t) {
        in_order = counting.stitched(done) && in_order;
      };
      const g2s::PipelineMesh mesh = g2s::mesh_tiles(counting, options);
      const std::string where = fmt::format("{} in flight, {} threads", in_flight, threads);
      EXPECT_TRUE(in_order) << where;
      EXPECT_LE(counting.most_ahead(), in_flight) << where;
      EXPECT_TRUE(mesh.triangles == one.triangles) << where;
    }
  }
}

// With the first tile growing, a second thread starts the tile of most points among those it may
// start (the tiles_in_flight from the first), so that large tiles do not come last.
TEST(MeshTiles, StartsTheLargestTileItMayWhileTheFirstGrows) {
  const g2s::PointCloud cloud = synthetic(g2s::SynthShape::torus, 20000);
  g2s::TileBox all;
  for (int a = 0; a < 3; ++a) {
    all.lo[a] = -1.5;
    all.hi[a] = 1.5;
  }
  // Slabs across x of unequal widths: the tiles' sizes differ.
  std::vector<g2s::TileBox> boxes;
  const std::array<double, 7> cuts = {-1.5, -0.9, -0.6, -0.1, 0.6, 0.8, 1.5};
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    g2s::TileBox box = all;
    box.lo[0] = cuts[k];
    box.hi[0] = cuts[k + 1];
    boxes.push_back(box);
  }
  const g2s::MemoryTiles tiles(cloud, boxes);
  const std::span<const g2s::TileInfo> info = tiles.tiles();
  for (const std::size_t in_flight : {2, 4, 6}) {
    CountingTiles counting(tiles, std::numeric_limits<std::size_t>::max(), true);
    g2s::PipelineOptions options;
    options.threads = 2;
    options.tiles_in_flight = in_flight;
    g2s::mesh_tiles(counting, options);
    std::size_t largest = 1;
    for (std::size_t t = 2; t < in_flight; ++t) {
      if (info[t].points > info[largest].points) largest = t;
    }
    EXPECT_EQ(counting.first_two_begun(), std::make_pair(std::size_t{0}, largest))
        << in_flight << " in flight";
  }
  EXPECT_GT(info[3].points, std::max({info[1].points, info[2].points}));  // the slabs differ
}

TEST(MeshTiles, ATileThatFailsStopsTheRunWithItsError) {
  const g2s::PointCloud cloud = synthetic(g2s::SynthShape::sphere, 10000);
  const g2s::MemoryTiles tiles(cloud, 1500);
  ASSERT_GE(tiles.tiles().size(), 6u);
  for (const std::size_t failing : {std::size_t{0}, std::size_t{3}}) {
    for (int threads = 1; threads <= 3; ++threads) {
      const CountingTiles counting(tiles, failing);
      g2s::PipelineOptions options;
      options.threads = threads;
      try {
        g2s::mesh_tiles(counting, options);
        ADD_FAILURE() << "tile " << failing << " failed, " << threads << " threads: no error";
      } catch (const g2s::Error& e) {
        EXPECT_EQ(e.code(), g2s::Exit::bad_input);
        EXPECT_STREQ(e.what(), "tile cannot be read");
      }
    }
  }
}

}  // namespace
