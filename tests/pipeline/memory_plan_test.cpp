// plan_memory (docs/pipeline.md, "Memory"): the tile size depends on the budget alone, never on
// the threads; the threads set the tiles in flight, a tile growing per thread and as many waiting
// for the stitcher when the budget holds them, at least one.
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
    EXPECT_EQ(g2s::plan_memory(8192 * kMiB, threads).tiles_in_flight,
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

}  // namespace
