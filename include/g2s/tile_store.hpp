// The tile store (src/tiling/, docs/tile-store.md): a cloud cut once into
// spatial point tiles on disk, so that each stage of the out-of-core pipeline loads only the
// tiles it works on. One file: a versioned header, the tile table, then one block per tile
// holding its points (double x, y, z) with their global ids, raw or zstd-compressed, each with
// a checksum. Within a block, points are ordered by increasing distance to the tile's box
// boundary, so the halo a neighbour needs is a prefix of the block.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "g2s/io.hpp"
#include "g2s/types.hpp"

namespace g2s {

// An axis-aligned box. A tile owns the points p with lo <= p < hi on every axis; the tiles of a
// store partition the cloud's bounding box (the outermost faces lie on it and own their points).
struct TileBox {
  double lo[3] = {0, 0, 0};
  double hi[3] = {0, 0, 0};
};

// Points that fall in two groups along an axis, with a gap between them this many times wider
// than either group, are cut apart through the gap whatever their count (docs/tile-store.md,
// "Adaptive split"): in one float frame (the mesher's) the rounding at the far group would reach
// about a tenth of the spacing of a million-point tile. So stray points far from a scan (invalid
// returns left at the origin of georeferenced coordinates) get tiles of their own, and the
// scan's tiles keep frames near their points.
inline constexpr double kStrayGap = 1000;

struct TileInfo {
  TileBox box;
  std::uint64_t points = 0;  // points stored in the tile
  double spacing = 0.0;      // estimated mean nearest-neighbour spacing of its points (0 if < 2)
  // The smallest box holding the tile's points (box for a tile of none), inside box. The tile's
  // float frame is centred on it: a box stretched by stray points far from the rest would put
  // the frame's origin far from the tile's points, where float is coarse.
  TileBox points_box;
};

struct TileStoreOptions {
  // No tile holds more (adaptive split); the one exception is a tile of more than tile_points
  // copies of a single point, which no plane can separate.
  std::uint64_t tile_points = std::uint64_t{1} << 20;
  // At least this many tiles, so that several threads have tiles to grow: once the cloud's
  // point count is known, the largest tile is lowered to count / min_tiles, but never below
  // min_tile_points (smaller clouds are fewer tiles). 1: tile_points alone decides.
  std::uint64_t min_tiles = 1;
  std::uint64_t min_tile_points = 16384;
  bool compress = false;  // zstd-compress the point blocks
  int zstd_level = 1;
  // Points the writer holds in memory at once (28 bytes each; at least tile_points): the bound
  // on its memory. A larger cloud is written in several rounds of whole tiles, read back from
  // a temporary spill file beside the store (28 bytes a point) that one pass over the input
  // fills. Added with the implementation: the memory bound is the caller's to choose, and the
  // tests need several rounds without a 100M-point file. The bytes written do not depend on it.
  std::uint64_t round_points = std::uint64_t{8} << 20;
  // Called now and then with (points done, points in total) while writing; may be empty.
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

// The largest tile for a cloud of `total` points under `options` (tile_points, lowered to
// total / min_tiles but not below min_tile_points).
inline std::uint64_t largest_tile_points(const TileStoreOptions& options, std::uint64_t total) {
  if (options.min_tiles <= 1) return options.tile_points;
  const std::uint64_t share = (total + options.min_tiles - 1) / options.min_tiles;
  return std::min(options.tile_points, std::max(share, options.min_tile_points));
}

struct TileStoreReport {
  ReadReport read;  // what the input reader saw (format, finite and non-finite points)
  std::uint64_t tiles = 0;
  std::uint64_t bytes = 0;  // size of the store file
};

// What a store was made from, so a kept store is reused only for the same input and tiling:
// the input's size, modification time (ns), a content fingerprint (XXH64 of its first and last
// MiB and its size: cheap however large the file), a hash of its absolute path, and the
// tile_points option (the only option that changes which points share a tile).
struct StoreOrigin {
  std::uint64_t bytes = 0;
  std::int64_t mtime_ns = 0;
  std::uint64_t content = 0;
  std::uint64_t path = 0;
  std::uint64_t tile_points = 0;
  bool operator==(const StoreOrigin&) const = default;
};

// The origin a store built now from `input` with `tile_points` would record. Throws
// Error(bad_input) when the input cannot be opened or read.
StoreOrigin store_origin(const std::filesystem::path& input, std::uint64_t tile_points);

// Whether a kept store at `store` can be reused for `input` cut with `tile_points`: it was made
// from this input (StoreOrigin) with this tiling. When not (none there, another input or
// tiling, another version or damaged), returns false and, if there was a store, why in `why`.
// A file there that is no tile store throws Error(usage): it is refused rather than overwritten.
bool kept_store_matches(const std::filesystem::path& store, const std::filesystem::path& input,
                        std::uint64_t tile_points, std::string& why);

// Reads `input` (any format read_points accepts) in streaming passes with bounded memory and
// writes the store atomically at `store` (temporary name, renamed when complete). Global ids
// are the points' order among the finite points of the input, as read_points numbers them.
// Deterministic: the same input and options give the same bytes. Throws Error(bad_input) for
// a bad input and Error(write_failed) when the store cannot be written.
TileStoreReport build_tile_store(const std::filesystem::path& input,
                                 const std::filesystem::path& store,
                                 const TileStoreOptions& options);

// The points of one tile (or a border prefix of it): xyz holds 3 doubles per point, ids their
// global ids.
struct TilePoints {
  std::vector<double> xyz;
  std::vector<Index> ids;
  std::size_t size() const { return ids.size(); }
};

// Where the pipeline's points come from (include/g2s/pipeline.hpp): a tile store, or tiles cut
// in memory (MemoryTiles).
class TileSource {
 public:
  virtual ~TileSource() = default;
  virtual std::span<const TileInfo> tiles() const = 0;
  // The median distance from a point of the cloud to its nearest neighbour (past its near-copies
  // in a cloud of twins), from a sample of about 65,536 points chosen by id (0 if there are
  // none): nearly the same for any tiling.
  virtual double cloud_spacing() const = 0;
  // Where the cloud's points come in groups closer than its sampling (LiDAR returns in pairs,
  // twins), the distance beyond which a point's nearest neighbour measures the spacing (every
  // grid measures it so, whatever its own sample says); 0 otherwise.
  virtual double group_distance() const = 0;
  // In a cloud of twins (most points come with a near-copy: the same surface scanned twice and
  // merged), the distance below which two points are taken as one sample; 0 otherwise.
  virtual double twin_distance() const = 0;
  virtual TilePoints load(std::size_t tile) const = 0;
  // At least the points within `distance` of the tile box's boundary (more is allowed).
  virtual TilePoints load_border(std::size_t tile, double distance) const = 0;
  std::uint64_t point_count() const;  // points in all tiles
};

// A cloud cut into tiles in memory: by a k-d split at medians until no tile holds more than
// tile_points, or by given boxes (which must partition the cloud's bounding box; tests use them
// to put seams exactly where they want).
class MemoryTiles final : public TileSource {
 public:
  MemoryTiles(const PointCloud& cloud, std::uint64_t tile_points);
  MemoryTiles(const PointCloud& cloud, std::vector<TileBox> boxes);
  std::span<const TileInfo> tiles() const override { return info_; }
  double cloud_spacing() const override { return cloud_spacing_; }
  double group_distance() const override { return group_distance_; }
  double twin_distance() const override { return twin_distance_; }
  TilePoints load(std::size_t tile) const override;
  TilePoints load_border(std::size_t tile, double distance) const override;

 private:
  void finish(std::vector<std::vector<Index>> members, const TileBox& bounds);
  const PointCloud& cloud_;
  double cloud_spacing_ = 0;
  double group_distance_ = 0;
  double twin_distance_ = 0;
  std::vector<TileInfo> info_;
  std::vector<std::vector<Index>> members_;  // per tile: ids of its points
};

// A store opened for reading: the header and table are validated on open; a block's checksum
// is checked each time it is loaded. Any corruption, truncation or version mismatch throws
// Error(bad_input, "<store>: ...") naming what is wrong. Safe to load from several threads.
class TileStore final : public TileSource {
 public:
  explicit TileStore(const std::filesystem::path& store);
  ~TileStore() override;
  TileStore(const TileStore&) = delete;
  TileStore& operator=(const TileStore&) = delete;

  const std::filesystem::path& path() const;
  const TileBox& bounds() const;  // bounding box of all points
  std::span<const TileInfo> tiles() const override;
  double cloud_spacing() const override;
  double group_distance() const override;
  double twin_distance() const override;
  const ReadReport& input_report() const;  // as build_tile_store saw the input
  bool compressed() const;                 // blocks are zstd frames (for g2s tile-info)
  const StoreOrigin& origin() const;       // what it was made from

  // All points of a tile.
  TilePoints load(std::size_t tile) const override;
  // The points of a tile within `distance` of its box's boundary (the halo its neighbours
  // need): a prefix of the block, so only that part is read (and decompressed).
  TilePoints load_border(std::size_t tile, double distance) const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace g2s
