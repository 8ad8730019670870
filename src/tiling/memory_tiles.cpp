// Tiles cut in memory (MemoryTiles): the TileSource for a cloud already read, and for tests that
// place seams by hand. The k-d split mirrors the tile store's: longest axis, at the median
// coordinate, until no tile holds more than its budget.
#include <algorithm>
#include <numeric>

#include "g2s/error.hpp"
#include "g2s/pipeline.hpp"
#include "grid/hash_grid.hpp"
#include "pipeline/tile_geometry.hpp"

namespace g2s {
namespace {

TileBox bounding_box(const PointCloud& cloud) {
  TileBox box;
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = cloud.size() ? cloud.xyz[a] : 0.0;
    box.hi[a] = box.lo[a];
  }
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = std::min(box.lo[a], cloud.xyz[3 * i + a]);
      box.hi[a] = std::max(box.hi[a], cloud.xyz[3 * i + a]);
    }
  }
  return box;
}

void split(const PointCloud& cloud, TileBox box, std::span<Index> ids, std::uint64_t budget,
           std::vector<TileBox>& boxes, std::vector<std::vector<Index>>& members) {
  if (ids.size() > budget) {
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
      if (box.hi[a] - box.lo[a] > box.hi[axis] - box.lo[axis]) axis = a;
    }
    auto coord = [&](Index i) { return cloud.xyz[3 * std::size_t{i} + axis]; };
    auto mid = ids.begin() + static_cast<long>(ids.size() / 2);
    std::nth_element(ids.begin(), mid, ids.end(),
                     [&](Index a, Index b) { return coord(a) < coord(b); });
    const double at = coord(*mid);
    const auto cut = std::partition(ids.begin(), ids.end(), [&](Index i) { return coord(i) < at; });
    if (cut != ids.begin() && cut != ids.end()) {
      TileBox low = box, high = box;
      low.hi[axis] = at;
      high.lo[axis] = at;
      split(cloud, low, {ids.begin(), cut}, budget, boxes, members);
      split(cloud, high, {cut, ids.end()}, budget, boxes, members);
      return;
    }
  }
  boxes.push_back(box);
  members.emplace_back(ids.begin(), ids.end());
  std::sort(members.back().begin(), members.back().end());
}

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
  std::vector<Index> ids(cloud.size());
  std::iota(ids.begin(), ids.end(), Index{0});
  std::vector<TileBox> boxes;
  std::vector<std::vector<Index>> members;
  split(cloud, bounding_box(cloud), ids, std::max<std::uint64_t>(tile_points, 1), boxes, members);
  for (const TileBox& box : boxes) info_.push_back({box, 0, 0.0});
  finish(std::move(members));
}

MemoryTiles::MemoryTiles(const PointCloud& cloud, std::vector<TileBox> boxes) : cloud_(cloud) {
  const TileBox bounds = bounding_box(cloud);
  std::vector<std::vector<Index>> members(boxes.size());
  for (Index i = 0; i < cloud.size(); ++i) {
    const double* p = &cloud.xyz[3 * std::size_t{i}];
    std::size_t owner = 0;
    while (owner < boxes.size() && !owns(boxes[owner], bounds, p)) ++owner;
    if (owner == boxes.size()) throw Error(Exit::failure, "MemoryTiles: boxes miss a point");
    members[owner].push_back(i);
  }
  for (const TileBox& box : boxes) info_.push_back({box, 0, 0.0});
  finish(std::move(members));
}

void MemoryTiles::finish(std::vector<std::vector<Index>> members) {
  members_ = std::move(members);
  for (std::size_t t = 0; t < info_.size(); ++t) {
    info_[t].points = members_[t].size();
    const TilePoints points = load(t);
    std::vector<float> local(points.xyz.size());
    for (std::size_t k = 0; k < local.size(); ++k) {
      local[k] = static_cast<float>(points.xyz[k] - info_[t].box.lo[k % 3]);
    }
    info_[t].spacing = points.size() < 2 ? 0.0 : HashGrid(local, points.ids).spacing();
  }
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
