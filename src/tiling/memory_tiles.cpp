// Tiles cut in memory (MemoryTiles): the TileSource for a cloud already read, and for tests that
// place seams by hand. The split is the tile store's (src/tiling/tile_split.hpp) on every point,
// so a cloud small enough for the store to sample whole gets the same tiles either way.
#include <tbb/parallel_for.h>

#include <algorithm>

#include "g2s/error.hpp"
#include "g2s/tile_store.hpp"
#include "tiling/tile_geometry.hpp"
#include "tiling/tile_spacing.hpp"
#include "tiling/tile_split.hpp"

namespace g2s {
namespace {

// Owner of a point among boxes that partition the bounding box: half-open, except on the
// bounding box's own upper faces.
bool owns(const TileBox& box, const TileBox& bounds, const double* p) {
  for (int a = 0; a < 3; ++a) {
    if (p[a] < box.lo[a]) return false;
    if (p[a] > box.hi[a] || (p[a] == box.hi[a] && box.hi[a] != bounds.hi[a])) return false;
  }
  return true;
}

}  // namespace

std::uint64_t TileSource::point_count() const {
  std::uint64_t n = 0;
  for (const TileInfo& t : tiles()) n += t.points;
  return n;
}

MemoryTiles::MemoryTiles(const PointCloud& cloud, std::uint64_t tile_points) : cloud_(cloud) {
  if (cloud.size() > kNoIndex) throw Error(Exit::bad_input, "cloud has more than 2^32-1 points");
  // The tile store's split, on every point (its exact case).
  tiling::PointSample sample(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) sample.add(&cloud.xyz[3 * i], i);
  const TileBox bounds = points_box(cloud.xyz, TileBox{});
  tiling::TileTree tree(bounds);
  if (cloud.size() > 0) {
    const double budget = static_cast<double>(std::max<std::uint64_t>(tile_points, 1));
    tree.split(0, sample, 1.0, budget);
    tree.taper(sample, 1.0, tiling::kLastTileShare * budget);
  }
  const std::vector<std::uint32_t> leaves =
      cloud.size() > 0 ? tree.leaves() : std::vector<std::uint32_t>{};
  std::vector<std::uint32_t> tile_of_node(tree.node_count(), kNoIndex);
  for (std::uint32_t t = 0; t < leaves.size(); ++t) {
    tile_of_node[leaves[t]] = t;
    info_.push_back({tree.box(leaves[t]), 0, 0.0, tree.box(leaves[t])});
  }
  std::vector<std::vector<Index>> members(leaves.size());
  for (Index i = 0; i < cloud.size(); ++i) {
    members[tile_of_node[tree.leaf_of(&cloud.xyz[3 * std::size_t{i}])]].push_back(i);
  }
  finish(std::move(members), bounds);
}

MemoryTiles::MemoryTiles(const PointCloud& cloud, std::vector<TileBox> boxes) : cloud_(cloud) {
  const TileBox bounds = points_box(cloud.xyz, TileBox{});
  std::vector<std::vector<Index>> members(boxes.size());
  for (Index i = 0; i < cloud.size(); ++i) {
    const double* p = &cloud.xyz[3 * std::size_t{i}];
    std::size_t owner = 0;
    while (owner < boxes.size() && !owns(boxes[owner], bounds, p)) ++owner;
    if (owner == boxes.size()) throw Error(Exit::failure, "MemoryTiles: boxes miss a point");
    members[owner].push_back(i);
  }
  for (const TileBox& box : boxes) info_.push_back({box, 0, 0.0, box});
  finish(std::move(members), bounds);
}

void MemoryTiles::finish(std::vector<std::vector<Index>> members, const TileBox& bounds) {
  members_ = std::move(members);
  // The tiles' spacings in parallel (as the tile store measures them), gathered in tile order.
  std::vector<tiling::TileSpacing> tiles(info_.size());
  tbb::parallel_for(std::size_t{0}, info_.size(), [&](std::size_t t) {
    info_[t].points = members_[t].size();
    const TilePoints points = load(t);
    info_[t].points_box = points_box(points.xyz, info_[t].box);
    tiles[t] =
        tiling::measure_tile_spacing(points.xyz, points.ids, info_[t].box, bounds, cloud_.size());
    info_[t].spacing = tiles[t].mean;
  });
  std::vector<NearestThree> cloud_sample;
  for (const tiling::TileSpacing& s : tiles) {
    cloud_sample.insert(cloud_sample.end(), s.cloud_sample.begin(), s.cloud_sample.end());
  }
  const tiling::CloudSpacing spacing = tiling::cloud_spacing(cloud_sample);
  cloud_spacing_ = spacing.spacing;
  group_distance_ = spacing.group_distance;
  twin_distance_ = spacing.twin_distance;
}

TilePoints MemoryTiles::load(std::size_t tile) const {
  TilePoints out;
  out.ids = members_[tile];
  out.xyz.reserve(3 * out.ids.size());
  for (Index i : out.ids) {
    for (int a = 0; a < 3; ++a) out.xyz.push_back(cloud_.xyz[3 * std::size_t{i} + a]);
  }
  return out;
}

TilePoints MemoryTiles::load_border(std::size_t tile, double distance) const {
  const TileBox& box = info_[tile].box;
  TilePoints out;
  for (Index i : members_[tile]) {
    const double* p = &cloud_.xyz[3 * std::size_t{i}];
    double inside = distance + 1;
    for (int a = 0; a < 3; ++a) inside = std::min({inside, p[a] - box.lo[a], box.hi[a] - p[a]});
    if (inside > distance) continue;
    out.ids.push_back(i);
    out.xyz.insert(out.xyz.end(), p, p + 3);
  }
  return out;
}

}  // namespace g2s
