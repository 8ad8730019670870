// Box geometry shared by the pipeline's stages: distances between points and tile boxes, the
// tiles near a tile, the local float frame a tile is meshed in, and how far a seam reaches.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "g2s/pipeline.hpp"
#include "g2s/tile_store.hpp"

namespace g2s {

// The origin, on one axis, of the local float frame for points in [lo, hi] (and a margin as wide
// again on each side, for halos): 0 when that range reaches the origin or lies near it for its
// width, else the range's centre rounded to a multiple of the float spacing at the range's
// smallest magnitude. Either way a coordinate read as float minus the origin is again a float,
// exactly, so the mesher decides on the very coordinates the output holds (its crossing test
// depends on it), while georeferenced coordinates keep their precision.
inline double frame_origin(double lo, double hi) {
  const double width = hi - lo;
  const double near = std::min(std::abs(lo - width), std::abs(hi + width));
  if ((lo - width <= 0 && hi + width >= 0) || !(2 * width < near)) return 0;
  int exponent = 0;
  std::frexp(near, &exponent);  // near = f * 2^exponent, f in [0.5, 1)
  const double step = std::ldexp(1.0, exponent - 24);
  return std::round(0.5 * (lo + hi) / step) * step;
}

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

inline bool box_contains(const TileBox& box, const double* p) {
  for (int a = 0; a < 3; ++a) {
    if (p[a] < box.lo[a] || p[a] > box.hi[a]) return false;
  }
  return true;
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

// Seam widths at a tile, in the largest spacing around it (local_spacing): the band grown, the
// context loaded around it, and how far from the tile's box a triangle made at its seam can
// reach (a band point, or a corner of a live triangle touching one: an edge is at most about
// a search ball of max_radius spacings, and a longer one is caught: the triangle is dropped
// and counted).
struct SeamReach {
  double band = 0;
  double context = 0;
  double touch = 0;
  double margin = 0;  // the release margin beyond `touch`: the longest edge (two search balls)
};

inline SeamReach seam_reach(std::span<const TileInfo> tiles, std::size_t tile,
                            const PipelineOptions& options) {
  const double first = 2 * options.band_spacings * tiles[tile].spacing;
  const double spacing = local_spacing(tiles, tile, tiles_near(tiles, tile, first));
  SeamReach r;
  r.band = options.band_spacings * spacing;
  r.context = 2 * r.band;
  r.touch = std::max(r.context, r.band + options.mesh.max_radius * spacing);
  r.margin = 2 * options.mesh.max_radius * spacing;
  return r;
}

// How deep inside its box a point of `tile` must lie for no seam to reach it: the largest
// `touch` among the tile's own seam and those of the tiles whose seams reach into its box. With
// `margin`, the depth beyond which the point is also out of reach of the release margin: its
// triangles are final when the tile is grown.
inline double seam_depth(std::span<const TileInfo> tiles, std::size_t tile,
                         const PipelineOptions& options, bool margin = false) {
  double largest_spacing = 0;
  for (const TileInfo& t : tiles) largest_spacing = std::max(largest_spacing, t.spacing);
  // No tile's reach exceeds this (its local spacing is at most the largest).
  const double bound =
      (std::max(2 * options.band_spacings, options.band_spacings + options.mesh.max_radius) +
       (margin ? 2 * options.mesh.max_radius : 0.0)) *
      largest_spacing;
  auto reach_of = [&](std::size_t t) {
    const SeamReach r = seam_reach(tiles, t, options);
    return r.touch + (margin ? r.margin : 0.0);
  };
  double depth = reach_of(tile);
  for (std::size_t j : tiles_near(tiles, tile, bound)) {
    const double reach = reach_of(j);
    if (box_gap(tiles[tile].box, tiles[j].box) <= reach) depth = std::max(depth, reach);
  }
  return depth;
}

}  // namespace g2s
