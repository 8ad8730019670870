// The tiled pipeline's two stages (docs/pipeline.md), each usable on its own: grow_tile grows one
// tile with a halo of its neighbours' points; the Stitcher takes the grown tiles in index order,
// stitches their seams, cleans up and hands the mesh to a sink. g2s/pipeline.hpp runs them
// together (mesh_tiles, mesh_cloud) or apart (growth files, for `g2s grow` and `g2s stitch`).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "g2s/mesh_sink.hpp"
#include "g2s/mesher.hpp"
#include "g2s/tile_store.hpp"

namespace g2s {

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

// Per tile, the neighbours' points grow_tile takes into its halo (the tile's own points aside):
// with its own points, what a tile costs to grow (g2s tile-info shows it; docs/pipeline.md,
// "Memory"). Reads only the tiles' borders, in parallel.
std::vector<std::uint64_t> count_halo_points(const TileSource& source,
                                             const PipelineOptions& options);

// What a pipeline run did, besides the mesh itself.
struct PipelineSummary {
  MeshReport report;
  std::uint64_t tiles = 0;
  std::uint64_t triangles = 0;  // handed to the sink
  std::uint64_t vertices = 0;
  std::uint64_t triangles_stitched = 0;
  // Seam triangles left out because a corner was already finished (a triangle longer than the
  // stitcher's reach; 0 unless --max-radius is far above the band width), or because they cross
  // a live triangle the seam did not load (one touching only its context: very noisy clouds in
  // small tiles; 0 on the shared scans).
  std::uint64_t seam_triangles_dropped = 0;
  // Vertices whose fan a late deletion may have split after some of their triangles had left
  // (beyond the release margin; 0 in every test cloud).
  std::uint64_t vertices_unjudged = 0;
  // The most points the stitcher held at once: the band of unfinished seams, not the cloud.
  std::uint64_t peak_live_points = 0;
  double seconds_stitch = 0.0;
  // CPU seconds (thread clocks) of mesh_tiles' stages: growing and preparing (Stitcher::prepare),
  // summed over the tiles, and the stitcher's serial intake of the tiles (Stitcher::add: seams,
  // clean-up, and the sink's work as triangles go out).
  double cpu_seconds_grow = 0.0;
  double cpu_seconds_stitch = 0.0;
};

// A grown tile made ready for Stitcher::add by Stitcher::prepare: its points, and what the
// stitcher needs to know of them that does not depend on the tiles stitched before it.
class PreparedTile {
 public:
  PreparedTile();
  ~PreparedTile();
  PreparedTile(PreparedTile&&) noexcept;
  PreparedTile& operator=(PreparedTile&&) noexcept;

 private:
  friend class Stitcher;
  struct Data;
  std::unique_ptr<Data> data_;
};

// The seam stitcher and the global clean-up, fed tile by tile in index order (as tiles finish
// growing). A vertex is finished once every tile that could still touch it has been stitched:
// then its non-manifold fans are removed, and each triangle whose corners are all finished goes
// to the sink and leaves memory. finish() decides the orientation of the groups.
//
// Taking a tile in has two parts. prepare() does the work that needs only the tile and the
// tile layout: which points a later seam can reach and when each is finished and released, and
// the final triangles numbered and laid out as they will go to the sink. It reads nothing the
// stitcher changes, so several tiles may be prepared at once, on other threads, while add()
// runs (the pipeline prepares a tile where it grew). add() does the rest, in index order: the
// final triangles to the sink, the other triangles into the live mesh, the seams, the clean-up.
class Stitcher {
 public:
  Stitcher(const TileSource& source, const PipelineOptions& options, MeshSink& sink);
  ~Stitcher();
  Stitcher(const Stitcher&) = delete;
  Stitcher& operator=(const Stitcher&) = delete;
  // Throws Error(bad_input) if the growth does not fit the tile (a corner or id out of range).
  PreparedTile prepare(std::size_t tile, TileGrowth growth) const;
  void add(std::size_t tile, PreparedTile prepared);  // tile = 0, 1, 2, ...
  void add(std::size_t tile, TileGrowth growth) { add(tile, prepare(tile, std::move(growth))); }
  PipelineSummary finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The most points the Stitcher will hold at once over `source`'s tiles (PipelineSummary's
// peak_live_points, before any tile grows): each point a seam may look up, from its tile's step
// through the step that releases it, as Stitcher::prepare decides; the few points held only as
// corners of triangles not yet final, or as possible second fans, are not counted. Reads every
// tile once, in parallel. g2s mesh sizes its tiles by it under a tight --memory
// (docs/pipeline.md, "Memory").
std::uint64_t predict_peak_live_points(const TileSource& source, const PipelineOptions& options);

}  // namespace g2s
