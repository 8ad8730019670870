// The tiled pipeline in one process: every tile grown as a TBB task (tiles are independent, so
// the result does not depend on the thread count), then the seams stitched in tile order.
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <memory>

#include "g2s/pipeline.hpp"

namespace g2s {

PipelineMesh mesh_tiles(const TileSource& source, const PipelineOptions& options) {
  std::unique_ptr<tbb::global_control> limit;
  if (options.threads > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(options.threads));
  }
  std::vector<TileGrowth> growths(source.tiles().size());
  tbb::parallel_for(std::size_t{0}, growths.size(),
                    [&](std::size_t t) { growths[t] = grow_tile(source, t, options); });
  return stitch_tiles(source, std::move(growths), options);
}

}  // namespace g2s
