// A cloud cut into a tile store for a memory budget, as `g2s mesh` and the Python module's
// mesh_file cut it (docs/pipeline.md, "Memory"): the tile the budget plans, at least
// kMinTiles tiles; then, when the budget bounds the tile, the band of open seams predicted from
// the tiles as cut and reserved, and the cloud cut again with smaller tiles while the largest
// tile does not fit beside it. Smaller tiles lengthen the seams, so the band is predicted again
// after each cut; at most two more cuts. Everything here depends on the input and the budget
// (or the tile asked for), never on the threads.
#include <algorithm>

#include "g2s/pipeline.hpp"

namespace g2s {

BudgetTiling tile_for_budget(const std::filesystem::path& input, const std::filesystem::path& store,
                             std::uint64_t budget_bytes, const PipelineOptions& options,
                             TileStoreOptions tiling, bool first_cut_made) {
  BudgetTiling out;
  out.plan = plan_memory(budget_bytes, options.threads);
  const bool planned = tiling.tile_points == 0;
  if (planned) {
    tiling.tile_points = out.plan.tile_points;
    tiling.min_tiles = out.plan.min_tiles;
  }
  const auto cut = [&] {
    tiling.round_points = std::max(out.plan.round_points, tiling.tile_points);
    out.read = build_tile_store(input, store, tiling).read;
    ++out.cuts;
  };
  if (!first_cut_made) cut();
  for (int again = 0; planned && out.plan.tile_bound_by_budget; ++again) {
    std::uint64_t largest = 0;
    {
      const TileStore cut_store(store);
      out.live_points = predict_peak_live_points(cut_store, options);
      for (const TileInfo& t : cut_store.tiles()) largest = std::max(largest, t.points);
    }
    if (budget_bytes < least_memory(out.live_points)) {
      out.band_needs = least_memory(out.live_points);
      break;
    }
    const MemoryPlan fitted = plan_memory(budget_bytes, options.threads, out.live_points);
    out.plan.tiles_in_flight = fitted.tiles_in_flight;
    if (largest <= fitted.tile_points || again == 2) break;
    tiling.tile_points = fitted.tile_points;
    cut();
  }
  return out;
}

}  // namespace g2s
