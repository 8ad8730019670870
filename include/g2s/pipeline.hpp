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

// The first stage's result for one tile: the triangles it keeps (all corners in the tile).
struct TileGrowth {
  std::vector<Triangle> triangles;   // global ids
  std::vector<std::uint32_t> group;  // per triangle: orientation group, 0..groups-1
  std::uint32_t groups = 0;          // triangles of one group face consistently
  // Global ids of the corners that may have more than one fan: where fronts met at a point,
  // and corners of triangles left out because they reach into the halo.
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
  // Called with (tiles stitched, tiles in total), from one thread at a time, after each tile;
  // may be empty. mesh.progress is not used.
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

// Grows one tile with its halo. Deterministic; independent of the other tiles.
TileGrowth grow_tile(const TileSource& source, std::size_t tile, const PipelineOptions& options);

struct PipelineMesh {
  std::vector<Triangle> triangles;  // global ids, oriented, manifold
  std::vector<double> xyz;          // 3 doubles per global id (points no triangle uses included)
  MeshReport report;
  std::uint64_t tiles = 0;
  std::uint64_t triangles_stitched = 0;
  double seconds_stitch = 0.0;
};

// The seam stitcher, fed tile by tile in index order (as tiles finish growing), then finished:
// the global non-manifold pass and the orientation of the components.
class Stitcher {
 public:
  Stitcher(const TileSource& source, const PipelineOptions& options);
  ~Stitcher();
  Stitcher(const Stitcher&) = delete;
  Stitcher& operator=(const Stitcher&) = delete;
  void add(std::size_t tile, TileGrowth growth);  // tile = 0, 1, 2, ...
  PipelineMesh finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Stitches the seams between grown tiles, removes non-manifold vertices and orients the
// components. growths[i] is grow_tile(source, i, options).
PipelineMesh stitch_tiles(const TileSource& source, std::vector<TileGrowth> growths,
                          const PipelineOptions& options);

// The tile store's identity for growth files: a hash of its tile table.
std::uint64_t source_fingerprint(const TileSource& source);

// Growth files, for `g2s grow` and `g2s stitch` in separate processes: written atomically, read
// back exactly; a file for another tile or store, a truncated or corrupt one throws
// Error(bad_input) naming the file and the fault.
void write_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                       std::uint64_t fingerprint, const TileGrowth& growth);
TileGrowth read_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                            std::uint64_t fingerprint);

// All stages in one process: grow_tile over every tile as TBB tasks, then stitch_tiles.
PipelineMesh mesh_tiles(const TileSource& source, const PipelineOptions& options);

}  // namespace g2s
