// The sampling spacing of one tile, stored in the tile table so that a pipeline stage can size
// its halo and its grid before loading any points, and the tile's part of the whole cloud's
// spacing, stored in the header: the mesher's search radius never falls below what the cloud's
// spacing allows, whatever the tiling (docs/algorithm.md, "Search balls").
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/sample_spacing.hpp"
#include "g2s/tile_store.hpp"
#include "g2s/types.hpp"

namespace g2s::tiling {

struct TileSpacing {
  // Mean spacing distance (common/sample_spacing.hpp: the distance to the nearest distinct
  // neighbour, past groups where the tile's own sample has them) of up to 4096 of the points
  // (every k-th); 0 for fewer than 2 distinct points.
  double mean = 0.0;
  // The three nearest-neighbour distances of the tile's points sampled for the cloud (about
  // 65,536 over the whole cloud, chosen by a hash of their ids) but those within 4 tile spacings
  // of a seam: their distances in the whole cloud wherever these are below 4 tile spacings.
  std::vector<NearestThree> cloud_sample;
};

// Inputs: the tile's points (xyz, 3 doubles per point, and their global ids), its box, the
// cloud's bounds (faces of the box on them have no tile beyond), the cloud's point count.
// Output: the tile's spacing and its part of the cloud's sample. Distances are exact, found
// through a grid of cells about two spacings wide; points with no neighbour within 16 cells are
// outliers and left out.
TileSpacing measure_tile_spacing(std::span<const double> xyz, std::span<const Index> ids,
                                 const TileBox& box, const TileBox& bounds,
                                 std::uint64_t cloud_points);

struct CloudSpacing {
  double spacing = 0;         // the median spacing distance (0 if there are no samples)
  double group_distance = 0;  // where points come in groups, the distances' lower cut; else 0
  double twin_distance = 0;   // in a cloud of twins, the near-copies' reach; 0 otherwise
};

// The cloud's spacing from all the tiles' cloud samples. Nearly the same for any tiling: which
// points near the seams are left out does not depend on their distances, so the median is not
// biased (within 1% on a noisy torus in 500-point tiles).
CloudSpacing cloud_spacing(std::span<const NearestThree> sample);

}  // namespace g2s::tiling
