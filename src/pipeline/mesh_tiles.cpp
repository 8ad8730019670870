// The tiled pipeline in one process: tiles grown as TBB tasks (tiles are independent, so the
// result does not depend on the thread count) and stitched in tile order as they come.
#include <tbb/global_control.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <memory>

#include "g2s/pipeline.hpp"

namespace g2s {

PipelineMesh mesh_tiles(const TileSource& source, const PipelineOptions& options) {
  std::unique_ptr<tbb::global_control> limit;
  if (options.threads > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(options.threads));
  }
  // Tiles grow in parallel while the stitcher, one tile at a time in index order, closes the
  // seams of those already grown; a few tiles are in flight at once.
  const std::size_t tiles = source.tiles().size();
  const std::size_t workers =
      options.threads > 0 ? static_cast<std::size_t>(options.threads)
                          : static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  Stitcher stitcher(source, options);
  std::size_t next = 0;
  tbb::parallel_pipeline(
      2 * workers + 1,
      tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                          [&](tbb::flow_control& control) -> std::size_t {
                                            if (next == tiles) control.stop();
                                            return next++;
                                          }) &
          tbb::make_filter<std::size_t, std::pair<std::size_t, TileGrowth>>(
              tbb::filter_mode::parallel,
              [&](std::size_t t) {
                return std::pair{t, grow_tile(source, t, options)};
              }) &
          tbb::make_filter<std::pair<std::size_t, TileGrowth>, void>(
              tbb::filter_mode::serial_in_order, [&](std::pair<std::size_t, TileGrowth> grown) {
                stitcher.add(grown.first, std::move(grown.second));
                if (options.progress) options.progress(grown.first + 1, tiles);
              }));
  return stitcher.finish();
}

}  // namespace g2s
