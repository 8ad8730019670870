// The memory budget of `g2s mesh`, turned into tile sizes. What grows with the tile size: each
// thread growing a tile (its points, halo, hash grid, front and triangles), each tile grown and
// waiting for the stitcher (its points and kept triangles), and the stitcher taking in a tile
// (a live slot per point until the tile's interior is released). What does not: the band of
// open seams, a few tens of spacings wide, which grows with the cloud's extent and with its
// noise; when the budget bounds the tile, g2s mesh predicts it from the tiles as cut
// (predict_peak_live_points) and plans again with it reserved. The split below is an
// estimate: what was measured (/usr/bin/time -v) is a whole single-thread run of one 450k-point
// tile, 120 MB (about 270 bytes a point), and the resulting peaks, 262-286 MB for tori of 10M
// and 40M points under 512M (docs/benchmarks.md, "Memory"): the constants are conservative.
#include <fmt/core.h>
#include <tbb/info.h>
#include <unistd.h>

#include <algorithm>

#include "g2s/error.hpp"
#include "g2s/pipeline.hpp"

namespace g2s {
namespace {

constexpr double kGrowBytesPerPoint = 400;     // a tile being grown, with its halo
constexpr double kWaitingBytesPerPoint = 100;  // a grown tile waiting to be stitched
constexpr double kStitchBytesPerPoint = 150;   // the tile being stitched and released
constexpr double kFixedBytes = 20e6;  // code, libraries, TBB, buffers: a tiny cloud's whole run
// What the allocator may keep free for reuse: g2s mesh bounds each heap's two thresholds by a
// 64th of the budget and 32 MiB, and a run has at most 3-4 heaps (fit_heap_to_budget,
// tools/main.cpp; g2s itself keeps one): an eighth of the budget, at most 256 MiB.
constexpr double kMostRetained = 8 * 32.0 * 1048576;
double heap_retention(double budget) {
  return std::min(budget / 8, kMostRetained);
}
// A point the stitcher holds along the open seams: its live slot, id map entry and triangles,
// and its record in the defect count (heaptrack on alpe under --memory 128M: about 90 MB of heap
// at 389k live points, 231 bytes each; docs/pipeline.md "Memory").
constexpr double kLiveBytesPerPoint = 256;
constexpr double kStoreBytesPerPoint = 64;  // the tile store writer, per point of a round
// The largest default tile, when the budget allows it (docs/pipeline.md, "Tile size"): larger
// tiles save no time, and on photogrammetry each seam costs a few tenths of a second of serial
// stitching.
constexpr std::uint64_t kDefaultTile = std::uint64_t{1} << 20;
// Clouds are cut into at least this many tiles (of at least 16,384 points, TileStoreOptions),
// so that clouds from about 100k points up grow on several threads; a count of the input, not
// of the threads, so the mesh is the same for any --threads.
constexpr std::uint64_t kMinTiles = 4;
// Tiles growing at once that the tile size is planned for (more when the budget holds them).
constexpr double kPlannedGrowers = 2;
constexpr std::uint64_t kSmallestTile = 4096;
constexpr double kPlannedBytesPerPoint =
    kPlannedGrowers * kGrowBytesPerPoint + kWaitingBytesPerPoint + kStitchBytesPerPoint;

}  // namespace

std::uint64_t least_memory(std::uint64_t live_points) {
  const double needed = kFixedBytes + kLiveBytesPerPoint * static_cast<double>(live_points) +
                        kPlannedBytesPerPoint * kSmallestTile;
  // The least budget b with b - heap_retention(b) = needed.
  const double budget = needed <= 7 * kMostRetained ? needed * 8 / 7 : needed + kMostRetained;
  return static_cast<std::uint64_t>(budget) + 1;
}

MemoryPlan plan_memory(std::uint64_t budget_bytes, int threads, std::uint64_t live_points) {
  const auto workers = static_cast<std::size_t>(
      threads > 0 ? threads : std::max(1, tbb::info::default_concurrency()));
  // The tile size is sized for kPlannedGrowers tiles growing at once whatever --threads says, so
  // that the tiles, and with them the mesh, are the same for any thread count; the threads then
  // get as many tiles in flight as the budget holds at that size.
  const auto budget = static_cast<double>(budget_bytes);
  const double usable = budget - heap_retention(budget) - kFixedBytes -
                        kLiveBytesPerPoint * static_cast<double>(live_points);
  const double tile = usable / kPlannedBytesPerPoint;
  if (budget_bytes < least_memory(live_points)) {
    throw Error(Exit::usage,
                fmt::format("--memory {} MB is too small: at least {} MB", budget_bytes >> 20,
                            (least_memory(live_points) >> 20) + 1));
  }
  MemoryPlan plan;
  plan.tile_points = std::clamp(static_cast<std::uint64_t>(tile), kSmallestTile, kDefaultTile);
  plan.tile_bound_by_budget = plan.tile_points < kDefaultTile;
  plan.min_tiles = kMinTiles;
  const double tile_size = static_cast<double>(plan.tile_points);
  const double growers =
      (usable / tile_size - kWaitingBytesPerPoint - kStitchBytesPerPoint) / kGrowBytesPerPoint;
  const std::size_t growing =
      std::clamp(static_cast<std::size_t>(std::max(growers, 1.0)), std::size_t{1}, workers);
  // Grown tiles wait for the stitcher, which takes them in order: while one slow tile grows,
  // the other threads go on only as far as tiles may wait. As many may wait as threads grow,
  // when the budget holds them (at least one): a timeline of alpe (13 tiles of 84k-757k points,
  // 2 threads) showed a thread idle behind slow tiles for 2.6 s of a 46 s run.
  const double room =
      usable / tile_size - static_cast<double>(growing) * kGrowBytesPerPoint - kStitchBytesPerPoint;
  const auto waiting = static_cast<std::size_t>(std::max(1.0, room / kWaitingBytesPerPoint));
  plan.tiles_in_flight = growing + std::min(waiting, growing);
  plan.round_points = std::clamp(static_cast<std::uint64_t>(usable / kStoreBytesPerPoint),
                                 plan.tile_points, std::uint64_t{8} << 20);
  return plan;
}

std::uint64_t default_memory_budget() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return std::uint64_t{4} << 30;
  return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page) / 2;
}

}  // namespace g2s
