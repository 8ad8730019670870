// The tiled pipeline in one process: tiles grown as TBB tasks (tiles are independent, so the
// result does not depend on the thread count) and stitched in tile order as they come. The
// thread count applies to this call only: it runs in its own task arena (the caller's, when that
// has the wanted size), and other TBB users of the process keep theirs.
#include <tbb/info.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>
#include <time.h>

#include <atomic>
#include <memory>
#include <utility>

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
  std::size_t next = 0;
  std::atomic<std::uint64_t> grow_ns{0};
  std::uint64_t stitch_ns = 0;
  const auto run = [&] {
    tbb::parallel_pipeline(
        options.tiles_in_flight > 0 ? options.tiles_in_flight : 2 * workers,
        tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                            [&](tbb::flow_control& control) -> std::size_t {
                                              if (next == tiles) control.stop();
                                              return next++;
                                            }) &
            tbb::make_filter<std::size_t, std::pair<std::size_t, PreparedTile>>(
                tbb::filter_mode::parallel,
                [&](std::size_t t) {
                  const std::uint64_t start = thread_cpu_ns();
                  std::pair grown{t, stitcher.prepare(t, grow_tile(source, t, options))};
                  grow_ns += thread_cpu_ns() - start;
                  return grown;
                }) &
            tbb::make_filter<std::pair<std::size_t, PreparedTile>, void>(
                tbb::filter_mode::serial_in_order, [&](std::pair<std::size_t, PreparedTile> grown) {
                  const std::uint64_t start = thread_cpu_ns();
                  stitcher.add(grown.first, std::move(grown.second));
                  stitch_ns += thread_cpu_ns() - start;
                  if (options.progress) options.progress(grown.first + 1, tiles);
                }));
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
