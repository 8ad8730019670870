// The tiled pipeline (ALGORITHM.md §7, docs/pipeline.md): grow G2S in every tile with a halo of
// its neighbours' points, keeping the triangles whose corners all lie in the tile; stitch the
// seams tile by tile in a fixed order, each seam grown from the open edges of the triangles
// already kept around it; then the global non-manifold pass and the orientation of each
// component. A cloud that fits in one tile is the special case with nothing to stitch.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "g2s/mesh_sink.hpp"
#include "g2s/mesher.hpp"
#include "g2s/tile_store.hpp"

namespace g2s {

// A cloud cut into tiles in memory: by a k-d split at medians until no tile holds more than
// tile_points, or by given boxes (which must partition the cloud's bounding box; tests use them
// to put seams exactly where they want).
class MemoryTiles final : public TileSource {
 public:
  MemoryTiles(const PointCloud& cloud, std::uint64_t tile_points);
  MemoryTiles(const PointCloud& cloud, std::vector<TileBox> boxes);
  std::span<const TileInfo> tiles() const override { return info_; }
  TilePoints load(std::size_t tile) const override;
  TilePoints load_border(std::size_t tile, double distance) const override;

 private:
  void finish(std::vector<std::vector<Index>> members);
  const PointCloud& cloud_;
  std::vector<TileInfo> info_;
  std::vector<std::vector<Index>> members_;  // per tile: ids of its points
};

// The first stage's result for one tile: the triangles it keeps (all corners in the tile). Points
// are given by their index among the tile's points as TileSource::load returns them (the
// stitcher takes them in with no lookup by global id).
struct TileGrowth {
  std::vector<Triangle> triangles;  // indices into the tile's points
  // The first final_triangles triangles are final: every corner is out of reach of all seams
  // and clean-ups to come, so the stitcher hands them to the output as they are.
  std::size_t final_triangles = 0;
  std::vector<std::uint32_t> group;  // per triangle: orientation group, 0..groups-1
  std::uint32_t groups = 0;          // triangles of one group face consistently
  // Corners (indices into the tile's points) that may have more than one fan: where fronts met
  // at a point, and corners of triangles left out because they reach into the halo.
  std::vector<Index> second_fans;
  MeshReport report;
  // The tile's own points as grow_tile loaded them, handed on so the stitcher of the same
  // process does not load them again (growth files leave them out: `g2s stitch` loads them).
  TilePoints points;
};

struct PipelineOptions {
  MeshOptions mesh;
  int threads = 0;  // 0: all cores
  // Halo and seam band widths, in the largest spacing around the tile: a tile is grown with its
  // neighbours' points this far out; a seam is stitched over the points this close to it.
  double halo_spacings = 8.0;
  double band_spacings = 6.0;
  // Points, in Gabriel order, a seam edge tries after its Gabriel point fails to join.
  int stitch_retries = 4;
  // Tiles grown but not yet stitched, at most (their triangles wait in memory); 0: two per
  // thread.
  std::size_t tiles_in_flight = 0;
  // Called with (tiles stitched, tiles in total), from one thread at a time, after each tile;
  // may be empty. mesh.progress is not used.
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

// Grows one tile with its halo. Deterministic; independent of the other tiles.
TileGrowth grow_tile(const TileSource& source, std::size_t tile, const PipelineOptions& options);

// What a pipeline run did, besides the mesh itself.
struct PipelineSummary {
  MeshReport report;
  std::uint64_t tiles = 0;
  std::uint64_t triangles = 0;  // handed to the sink
  std::uint64_t vertices = 0;
  std::uint64_t triangles_stitched = 0;
  // Seam triangles left out because a corner was already finished (a triangle longer than the
  // stitcher's reach; 0 unless --max-radius is far above the band width).
  std::uint64_t seam_triangles_dropped = 0;
  // Vertices whose fan a late deletion may have split after some of their triangles had left
  // (beyond the release margin; 0 in every test cloud).
  std::uint64_t vertices_unjudged = 0;
  // The most points the stitcher held at once: the band of unfinished seams, not the cloud.
  std::uint64_t peak_live_points = 0;
  double seconds_stitch = 0.0;
};

// The whole mesh in memory (tests, small clouds): triangles in global ids, oriented, manifold.
struct PipelineMesh : PipelineSummary {
  std::vector<Triangle> triangles;
  std::vector<double> xyz;  // 3 doubles per global id (points no triangle uses are zero)
};

// The seam stitcher and the global clean-up, fed tile by tile in index order (as tiles finish
// growing). A vertex is finished once every tile that could still touch it has been stitched:
// then its non-manifold fans are removed, and each triangle whose corners are all finished goes
// to the sink and leaves memory. finish() decides the orientation of the groups.
class Stitcher {
 public:
  Stitcher(const TileSource& source, const PipelineOptions& options, MeshSink& sink);
  ~Stitcher();
  Stitcher(const Stitcher&) = delete;
  Stitcher& operator=(const Stitcher&) = delete;
  void add(std::size_t tile, TileGrowth growth);  // tile = 0, 1, 2, ...
  PipelineSummary finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The tile store's identity for growth files: a hash of its tile table.
std::uint64_t source_fingerprint(const TileSource& source);

// Growth files, for `g2s grow` and `g2s stitch` in separate processes: written atomically, read
// back exactly; a file for another tile or store, a truncated or corrupt one throws
// Error(bad_input) naming the file and the fault.
void write_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                       std::uint64_t fingerprint, const TileGrowth& growth);
TileGrowth read_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                            std::uint64_t fingerprint);

// All stages in one process: grow_tile over every tile as TBB tasks (at most
// options.tiles_in_flight grown and not yet stitched), stitched in order into `sink`.
PipelineSummary mesh_tiles(const TileSource& source, const PipelineOptions& options,
                           MeshSink& sink);

// The same, collecting the mesh in memory.
PipelineMesh mesh_tiles(const TileSource& source, const PipelineOptions& options);

// A whole cloud in memory, meshed as `g2s mesh` meshes it: cut into MemoryTiles of at most
// tile_points points (0: the size plan_memory chooses for the default budget and
// options.threads, as the CLI does), then mesh_tiles. Triangles index into cloud.xyz. Throws
// Error(bad_input) for more than 2^32-1 points.
PipelineMesh mesh_cloud(const PointCloud& cloud, const PipelineOptions& options = {},
                        std::uint64_t tile_points = 0);

// How `g2s mesh --memory` spends a budget of bytes (peak resident memory, as /usr/bin/time -v
// reports it): the largest tile, the tiles grown and waiting at once, and the points the tile
// store's writer sorts per round. Per-point costs measured on the synthetic torus, with the
// margin docs/pipeline.md gives; a budget too small for a workable tile throws Error(usage).
struct MemoryPlan {
  std::uint64_t tile_points = 0;
  std::size_t tiles_in_flight = 0;
  std::uint64_t round_points = 0;
};
MemoryPlan plan_memory(std::uint64_t budget_bytes, int threads);

// The default budget: half of the machine's physical memory.
std::uint64_t default_memory_budget();

}  // namespace g2s
