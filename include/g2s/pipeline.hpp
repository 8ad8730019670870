// The tiled pipeline (docs/pipeline.md): grow G2S in every tile with a halo of its neighbours'
// points, keeping the triangles whose corners all lie in the tile; stitch the seams tile by tile
// in a fixed order, each seam grown from the open edges of the triangles already kept around it;
// then the global non-manifold pass and the orientation of each component. A cloud that fits in
// one tile is the special case with nothing to stitch. The two stages themselves are in
// g2s/tile_stages.hpp; this header runs them (in one process, or apart through growth files)
// and plans their memory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "g2s/stats.hpp"
#include "g2s/stream_stats.hpp"
#include "g2s/tile_stages.hpp"
#include "g2s/tile_store.hpp"

namespace g2s {

// The whole mesh in memory (tests, small clouds): triangles in global ids, oriented, manifold.
struct PipelineMesh : PipelineSummary {
  std::vector<Triangle> triangles;
  std::vector<double> xyz;  // 3 doubles per global id (points no triangle uses are zero)
};

// The tile store's identity for growth files: a hash of its tile table.
std::uint64_t source_fingerprint(const TileSource& source);

// The options that change the mesh, for growth files: a hash of the MeshOptions (radius steps,
// flatness levels, max fold, max radius, seed ball, close_gaps, orient) and the halo, band and
// retries. Progress callbacks and thread counts are left out.
std::uint64_t options_fingerprint(const PipelineOptions& options);

// Growth files, for `g2s grow` and `g2s stitch` in separate processes: written atomically, read
// back exactly; a file for another tile or store, a truncated or corrupt one throws
// Error(bad_input) naming the file and the fault; one grown with other options (another
// `options` fingerprint) throws Error(usage).
void write_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                       std::uint64_t fingerprint, std::uint64_t options, const TileGrowth& growth);
TileGrowth read_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                            std::uint64_t fingerprint, std::uint64_t options);

// The defects of a mesh file written by streaming a run into `counter`, a StreamStats in front
// of the file's MeshStreamWriter, as `g2s mesh` reports them. The count, where it is the file's
// (in_stride): every triangle came before its vertices were done, and the file keeps the
// positions the count judged: binary PLY exactly (`stl` false); STL's 32-bit floats merge no
// vertices the stream saw apart while rounding (`float_rounding`,
// MeshStreamWriter::float_rounding()) moves them by at most a hundredth of the sampling
// `spacing`. Else the file read back and measured (compute_stats, crossing pairs included), if
// its `triangles` fit in `memory_bytes` (0: no limit) at kStatsBytesPerTriangle; else none.
struct WrittenMeshStats {
  std::optional<MeshStats> stats;
  bool in_stride = false;
};
WrittenMeshStats measure_written_mesh(const StreamStats& counter, const std::filesystem::path& file,
                                      bool stl, double float_rounding, double spacing,
                                      std::uint64_t triangles, std::uint64_t memory_bytes);
// What reading a mesh back and measuring it takes per triangle (STL welding, the stats' edge
// map): `g2s stats` on the 20M-triangle torus STL peaked at 1.70 GB (85 bytes a triangle); twice
// that leaves room for meshes with more vertices per triangle.
inline constexpr std::uint64_t kStatsBytesPerTriangle = 160;

// All stages in one process: grow_tile over every tile as TBB tasks (at most
// options.tiles_in_flight grown and not yet stitched), stitched in order into `sink`.
PipelineSummary mesh_tiles(const TileSource& source, const PipelineOptions& options,
                           MeshSink& sink);

// The same, collecting the mesh in memory.
PipelineMesh mesh_tiles(const TileSource& source, const PipelineOptions& options);

// A whole cloud in memory, meshed as `g2s mesh` meshes it: cut into MemoryTiles of at most
// tile_points points (0: the size plan_memory chooses for budget_bytes and options.threads, and
// at least the plan's minimum number of tiles, as the CLI does), then mesh_tiles, with the
// plan's tiles in flight unless options set them. budget_bytes 0: default_memory_budget().
// Triangles index into cloud.xyz. Throws Error(bad_input) for more than 2^32-1 points.
PipelineMesh mesh_cloud(const PointCloud& cloud, const PipelineOptions& options = {},
                        std::uint64_t tile_points = 0, std::uint64_t budget_bytes = 0);

// How `g2s mesh --memory` spends a budget of bytes (peak resident memory, as /usr/bin/time -v
// reports it): the largest tile, the tiles grown and waiting at once, and the points the tile
// store's writer sorts per round. Per-point costs measured on the synthetic torus and alpe, with
// the margin docs/pipeline.md gives. live_points: the points the stitcher will hold at once
// along its open seams (predict_peak_live_points, include/g2s/tile_stages.hpp), reserved before
// the tiles; 0 when not known yet. A budget below least_memory(live_points) throws Error(usage).
struct MemoryPlan {
  std::uint64_t tile_points = 0;
  std::uint64_t min_tiles = 1;  // TileStoreOptions::min_tiles: at least this many tiles
  std::size_t tiles_in_flight = 0;
  std::uint64_t round_points = 0;
  bool tile_bound_by_budget = false;  // tile_points is below the default tile for lack of memory
};
MemoryPlan plan_memory(std::uint64_t budget_bytes, int threads, std::uint64_t live_points = 0);
std::uint64_t least_memory(std::uint64_t live_points);

// Cuts `input` into the tile store at `store` for a memory budget, as g2s mesh does
// (src/pipeline/budget_tiling.cpp): tiling.tile_points 0 takes the tile plan_memory plans (at
// least plan.min_tiles tiles) and, when the budget bounds it, predicts the band of open seams
// from the tiles as cut (predict_peak_live_points) and cuts again smaller while the largest tile
// does not fit beside it (at most twice); a tile_points given is cut as given. first_cut_made:
// the store at `store` is already the first cut (a kept store cut with plan.tile_points), so
// only the band is checked. Outputs: the plan (its tiles_in_flight for the store as finally
// cut; tile_points the tile first planned), the read report of the last cut (empty when none
// was made), the band predicted (0 when not needed) and, when the budget cannot hold that band
// even with the smallest tiles, the least budget that would (band_needs; the store is then left
// as cut and the run may exceed the budget).
struct BudgetTiling {
  MemoryPlan plan;
  ReadReport read;
  int cuts = 0;
  std::uint64_t live_points = 0;
  std::uint64_t band_needs = 0;
};
BudgetTiling tile_for_budget(const std::filesystem::path& input, const std::filesystem::path& store,
                             std::uint64_t budget_bytes, const PipelineOptions& options,
                             TileStoreOptions tiling, bool first_cut_made);

// The default budget: half of the machine's physical memory.
std::uint64_t default_memory_budget();

}  // namespace g2s
