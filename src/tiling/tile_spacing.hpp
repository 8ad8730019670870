// The sampling spacing of one tile, stored in the tile table so that a pipeline stage can size
// its halo and its grid before loading any points.
#pragma once

#include <span>

namespace g2s::tiling {

// Mean distance from up to 4096 of the points (every k-th) to their nearest distinct
// neighbour, exact, found through a grid of cells about two spacings wide. xyz holds 3 doubles
// per point. Points with no neighbour within 16 cells are outliers and left out. 0 for fewer
// than 2 distinct points.
double estimate_tile_spacing(std::span<const double> xyz);

}  // namespace g2s::tiling
