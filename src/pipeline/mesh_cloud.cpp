// A cloud already in memory, meshed the way `g2s mesh` meshes a file: cut into tiles in memory
// (MemoryTiles, the tile store's split) of the size the CLI chooses (its memory plan, and at
// least the plan's minimum number of tiles), then grown, stitched and cleaned by mesh_tiles.
// Tests, benchmarks and library users thus run the code the CLI runs; a cloud smaller than a
// tile is one tile with nothing to stitch.
#include "g2s/pipeline.hpp"

namespace g2s {

PipelineMesh mesh_cloud(const PointCloud& cloud, const PipelineOptions& options,
                        std::uint64_t tile_points, std::uint64_t budget_bytes) {
  const MemoryPlan plan =
      plan_memory(budget_bytes > 0 ? budget_bytes : default_memory_budget(), options.threads);
  if (tile_points == 0) {
    TileStoreOptions tiling;
    tiling.tile_points = plan.tile_points;
    tiling.min_tiles = plan.min_tiles;
    tile_points = largest_tile_points(tiling, cloud.size());
  }
  PipelineOptions planned = options;
  if (planned.tiles_in_flight == 0) planned.tiles_in_flight = plan.tiles_in_flight;
  const MemoryTiles tiles(cloud, tile_points);
  return mesh_tiles(tiles, planned);
}

}  // namespace g2s
