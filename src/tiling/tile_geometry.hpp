// Box geometry of tiles, shared by the tiling and the pipeline's stages: distances between points
// and tile boxes, the bounds of all tiles, the tiles near a tile and their largest spacing.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "g2s/tile_store.hpp"

namespace g2s {

inline double box_distance(const TileBox& box, const double* p) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double gap = std::max({box.lo[a] - p[a], 0.0, p[a] - box.hi[a]});
    d2 += gap * gap;
  }
  return std::sqrt(d2);
}

inline double box_gap(const TileBox& a, const TileBox& b) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max({a.lo[k] - b.hi[k], 0.0, b.lo[k] - a.hi[k]});
    d2 += gap * gap;
  }
  return std::sqrt(d2);
}

// How far inside the box p lies: its distance to the nearest face (negative outside).
inline double box_depth(const TileBox& box, const double* p) {
  double depth = box.hi[0] - p[0];
  for (int a = 0; a < 3; ++a) depth = std::min({depth, p[a] - box.lo[a], box.hi[a] - p[a]});
  return depth;
}

// The bounding box of all tiles: the cloud's.
inline TileBox tiles_bounds(std::span<const TileInfo> tiles) {
  TileBox b = tiles.empty() ? TileBox{} : tiles[0].box;
  for (const TileInfo& t : tiles) {
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::min(b.lo[a], t.box.lo[a]);
      b.hi[a] = std::max(b.hi[a], t.box.hi[a]);
    }
  }
  return b;
}

// The tiles other than `tile` whose boxes lie within `reach` of its box, in index order.
inline std::vector<std::size_t> tiles_near(std::span<const TileInfo> tiles, std::size_t tile,
                                           double reach) {
  std::vector<std::size_t> near;
  for (std::size_t j = 0; j < tiles.size(); ++j) {
    if (j != tile && tiles[j].points > 0 && box_gap(tiles[tile].box, tiles[j].box) <= reach) {
      near.push_back(j);
    }
  }
  return near;
}

// The largest spacing of a tile and its neighbours: the unit of the halo and seam widths, so
// that a sparse neighbour still gets a halo wide enough for its triangles.
inline double local_spacing(std::span<const TileInfo> tiles, std::size_t tile,
                            std::span<const std::size_t> near) {
  double s = tiles[tile].spacing;
  for (std::size_t j : near) s = std::max(s, tiles[j].spacing);
  return s;
}

}  // namespace g2s
