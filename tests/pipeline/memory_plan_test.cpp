// plan_memory (docs/pipeline.md, "Memory"): the tile size depends on the budget alone, never on
// the threads; the threads set the tiles in flight, a tile growing per thread and as many waiting
// for the stitcher when the budget holds them, at least one. The band of open seams, once
// predicted from the tiles, is reserved before them.
#include <gtest/gtest.h>

#include <cstdint>

#include "g2s/error.hpp"
#include "g2s/pipeline.hpp"

namespace {

constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;

TEST(MemoryPlan, TheTileSizeIsTheSameForAnyThreadCount) {
  for (const std::uint64_t budget : {48 * kMiB, 64 * kMiB, 512 * kMiB, 8192 * kMiB}) {
    const g2s::MemoryPlan one = g2s::plan_memory(budget, 1);
    for (int threads = 2; threads <= 16; ++threads) {
      const g2s::MemoryPlan plan = g2s::plan_memory(budget, threads);
      EXPECT_EQ(plan.tile_points, one.tile_points) << budget / kMiB << "M, " << threads;
      EXPECT_EQ(plan.min_tiles, one.min_tiles);
      EXPECT_EQ(plan.round_points, one.round_points);
    }
  }
}

TEST(MemoryPlan, AsManyTilesWaitAsGrowWhenTheBudgetHoldsThem) {
  // A large budget: every thread grows a tile and as many grown tiles may wait.
  for (int threads = 1; threads <= 16; ++threads) {
    EXPECT_EQ(g2s::plan_memory(16384 * kMiB, threads).tiles_in_flight,
              2 * static_cast<std::size_t>(threads))
        << threads;
  }
}

TEST(MemoryPlan, ATightBudgetKeepsOneTileWaiting) {
  // 64 MB sizes the tile for two growing, one waiting and one being stitched: more threads get
  // no more tiles in flight, and one thread still has one tile waiting.
  EXPECT_EQ(g2s::plan_memory(64 * kMiB, 1).tiles_in_flight, 2u);
  for (int threads = 2; threads <= 8; ++threads) {
    EXPECT_EQ(g2s::plan_memory(64 * kMiB, threads).tiles_in_flight, 3u) << threads;
  }
}

TEST(MemoryPlan, ABudgetTooSmallIsRefused) {
  EXPECT_THROW(g2s::plan_memory(8 * kMiB, 2), g2s::Error);
}

// The band of open seams, once predicted, is reserved before the tiles: the more points the
// stitcher will hold, the smaller the tile, and a band the budget cannot hold with the smallest
// tile is refused, at the budget least_memory names.
TEST(MemoryPlan, TheSeamsBandIsReservedBeforeTheTiles) {
  const std::uint64_t budget = 256 * kMiB;
  const g2s::MemoryPlan none = g2s::plan_memory(budget, 2);
  EXPECT_TRUE(none.tile_bound_by_budget);
  EXPECT_FALSE(g2s::plan_memory(8192 * kMiB, 2).tile_bound_by_budget);
  std::uint64_t previous = none.tile_points;
  for (const std::uint64_t live : {50000u, 200000u, 400000u}) {
    const g2s::MemoryPlan plan = g2s::plan_memory(budget, 2, live);
    EXPECT_LT(plan.tile_points, previous) << live;
    previous = plan.tile_points;
  }
  const std::uint64_t least = g2s::least_memory(400000);
  EXPECT_GT(least, g2s::least_memory(0));
  EXPECT_NO_THROW(g2s::plan_memory(least, 2, 400000));
  EXPECT_THROW(g2s::plan_memory(least - 1, 2, 400000), g2s::Error);
}

}  // namespace
