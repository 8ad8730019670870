// How far the seam stitcher reaches from a tile's box, shared by the stitcher and grow_tile
// (which must know which of its points no seam can touch, to clean and hand them on early).
#pragma once

#include <algorithm>
#include <span>

#include "g2s/tile_stages.hpp"
#include "tiling/tile_geometry.hpp"

namespace g2s {

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
