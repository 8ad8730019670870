// The tiled pipeline in one process: tiles grown as TBB tasks (tiles are independent, so the
// result does not depend on the thread count) and stitched in tile order as they come. The
// thread count applies to this call only: it runs in its own task arena (the caller's, when that
// has the wanted size), and other TBB users of the process keep theirs.
#include <tbb/info.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>
#include <time.h>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "g2s/pipeline.hpp"

namespace g2s {
namespace {

// The mesh collected in memory, in global ids.
class MemorySink final : public MeshSink {
 public:
  explicit MemorySink(std::uint64_t points) { mesh.xyz.assign(3 * points, 0.0); }
  void vertex(Index id, const double xyz[3]) override {
    ids_.push_back(id);
    std::copy_n(xyz, 3, &mesh.xyz[3 * std::size_t{id}]);
  }
  void triangle(const Triangle& corners, const std::array<const double*, 3>&,
                std::uint32_t group) override {
    mesh.triangles.push_back({ids_[corners[0]], ids_[corners[1]], ids_[corners[2]]});
    group_.push_back(group);
  }
  void finish(std::span<const std::uint8_t> flip) override {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (flip[group_[t]]) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
    }
  }
  PipelineMesh mesh;

 private:
  std::vector<Index> ids_;  // by vertex number
  std::vector<std::uint32_t> group_;
};

// Grows tiles with at most `in_flight` of them grown or growing and not yet stitched, and
// stitches each, in index order, as soon as it and every tile before it have grown: the thread
// whose growth completes that run stitches it before it takes another tile to grow. A thread
// then starts the first tile not stitched if it is still waiting, so that stitching and the
// tokens it frees keep moving, and otherwise, of the tiles less than `in_flight` past it, the
// one of most points: large tiles taken last leave the other threads idle at the end (raw-bunny
// in index order on 2 threads: its largest tile, 0.4 s of growth, started last but two, and one
// thread waited 0.27 s of the 1.09 s). Starting only in that window never stalls: the tiles
// begun and not stitched are all in it, fewer than `in_flight`, so the first one not stitched
// has begun or can begin. (TBB's parallel_pipeline starts tiles in index order only, and
// spawns a waiting tile's stitch behind the next growth, so the stitches piled up after the
// last growth.) No thread waits for another; the calling thread takes part in the tasks until
// every tile is stitched, and the first exception of a task cancels the rest and is thrown.
// Which tile grows when changes no byte: tiles grow independently and are stitched in order.
class TileSchedule {
 public:
  using Grow = std::function<PreparedTile(std::size_t)>;
  using Stitch = std::function<void(std::size_t, PreparedTile)>;
  // Inputs: points per tile (the tiles' sizes), in_flight, and what growing and stitching a
  // tile are.
  TileSchedule(std::vector<std::uint64_t> points, std::size_t in_flight, Grow grow, Stitch stitch)
      : tiles_(points.size()),
        in_flight_(std::max<std::size_t>(in_flight, 1)),
        points_(std::move(points)),
        grow_(std::move(grow)),
        stitch_(std::move(stitch)),
        grown_(tiles_),
        state_(tiles_, kWaiting) {}

  void run() {
    {
      const std::lock_guard lock(mutex_);
      spawn_growth();
    }
    group_.wait();
  }

 private:
  // Starts growth tasks while tiles are left and tokens free (mutex_ held). A task chooses its
  // tile when it starts (next_tile).
  void spawn_growth() {
    while (spawned_ < tiles_ && spawned_ - stitched_ < in_flight_) {
      ++spawned_;
      group_.run([this] { grow_next(); });
    }
  }

  // The tile to start (mutex_ held): the first not stitched if it is waiting, else the waiting
  // tile of most points (the first of equals) among the in_flight_ from it. One is waiting
  // whenever a task starts (see above).
  std::size_t next_tile() const {
    if (state_[stitched_] == kWaiting) return stitched_;
    std::size_t best = tiles_;
    for (std::size_t t = stitched_ + 1; t < std::min(tiles_, stitched_ + in_flight_); ++t) {
      if (state_[t] == kWaiting && (best == tiles_ || points_[t] > points_[best])) best = t;
    }
    return best;
  }

  void grow_next() {
    std::size_t tile = 0;
    {
      const std::lock_guard lock(mutex_);
      tile = next_tile();
      state_[tile] = kGrowing;
    }
    PreparedTile grown = grow_(tile);
    {
      const std::lock_guard lock(mutex_);
      grown_[tile] = std::move(grown);
      state_[tile] = kGrown;
      if (stitching_) return;  // the stitching thread will find it
      stitching_ = true;
    }
    stitch_ready();
  }

  // Stitches tiles in index order while the next one has grown.
  void stitch_ready() {
    for (;;) {
      std::size_t tile = 0;
      PreparedTile grown;
      {
        const std::lock_guard lock(mutex_);
        if (stitched_ == tiles_ || state_[stitched_] != kGrown) {
          stitching_ = false;
          return;
        }
        tile = stitched_;
        grown = std::move(grown_[tile]);
      }
      stitch_(tile, std::move(grown));
      const std::lock_guard lock(mutex_);
      ++stitched_;
      spawn_growth();
    }
  }

  enum : std::uint8_t { kWaiting, kGrowing, kGrown };
  const std::size_t tiles_, in_flight_;
  const std::vector<std::uint64_t> points_;
  const Grow grow_;
  const Stitch stitch_;
  std::mutex mutex_;
  std::vector<PreparedTile> grown_;  // per tile, until stitched
  std::vector<std::uint8_t> state_;  // per tile
  std::size_t spawned_ = 0, stitched_ = 0;
  bool stitching_ = false;  // a thread is in stitch_ready
  tbb::task_group group_;
};

// CPU nanoseconds the calling thread has used.
std::uint64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<std::uint64_t>(t.tv_sec) * 1000000000u + static_cast<std::uint64_t>(t.tv_nsec);
}

}  // namespace

PipelineSummary mesh_tiles(const TileSource& source, const PipelineOptions& options,
                           MeshSink& sink) {
  const int wanted = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  // Tiles grow (and are prepared for the stitcher) in parallel while the stitcher, one tile at a
  // time in index order, closes the seams of those already grown; tiles_in_flight bounds the
  // tiles grown and waiting.
  const std::size_t tiles = source.tiles().size();
  const auto workers = static_cast<std::size_t>(wanted);
  Stitcher stitcher(source, options, sink);
  std::atomic<std::uint64_t> grow_ns{0};
  std::uint64_t stitch_ns = 0;  // one stitch at a time, ordered by the schedule's mutex
  const auto run = [&] {
    std::vector<std::uint64_t> points;
    for (const TileInfo& tile : source.tiles()) points.push_back(tile.points);
    TileSchedule(
        std::move(points), options.tiles_in_flight > 0 ? options.tiles_in_flight : 2 * workers,
        [&](std::size_t t) {
          const std::uint64_t start = thread_cpu_ns();
          PreparedTile grown = stitcher.prepare(t, grow_tile(source, t, options));
          grow_ns += thread_cpu_ns() - start;
          return grown;
        },
        [&](std::size_t t, PreparedTile grown) {
          const std::uint64_t start = thread_cpu_ns();
          stitcher.add(t, std::move(grown));
          stitch_ns += thread_cpu_ns() - start;
          if (options.progress) options.progress(t + 1, tiles);
        })
        .run();
  };
  // A new arena's threads come from the arena the caller ran in, and join it only once that
  // arena lets them go: on the 2-core VM the second thread began its first tile 0.08-0.14 s late
  // in 4 runs of 6 (the other tiles' order absorbed it: the same wall time). A caller already in
  // an arena of the wanted size (g2s mesh runs every stage in one) is not given a second.
  if (tbb::this_task_arena::max_concurrency() == wanted) {
    run();
  } else {
    tbb::task_arena(wanted).execute(run);
  }
  PipelineSummary summary = stitcher.finish();
  summary.cpu_seconds_grow = 1e-9 * static_cast<double>(grow_ns.load());
  summary.cpu_seconds_stitch = 1e-9 * static_cast<double>(stitch_ns);
  return summary;
}

PipelineMesh mesh_tiles(const TileSource& source, const PipelineOptions& options) {
  MemorySink sink(source.point_count());
  static_cast<PipelineSummary&>(sink.mesh) = mesh_tiles(source, options, sink);
  return std::move(sink.mesh);
}

}  // namespace g2s
