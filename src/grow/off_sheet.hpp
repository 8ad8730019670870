// One sheet through thick or layered regions (docs/algorithm.md, "One sheet through thick
// layers"). Where overlapping scans or noise make the points a layer thicker than their spacing,
// a surface through every point must zig-zag between the layer's faces, and the points that
// stick out furthest make the folds that end as crossings and holes. Per point, a smooth surface
// (a quadric height field over the plane fitted by PCA) is fitted to its nearest neighbours: it
// follows the layer's middle, curvature included, so that on a clean surface its residuals are
// the sampling's own, far below the spacing. Where the residuals' spread says the layer is thicker
// than the spacing, a point whose own residual is beyond two standard deviations is off the
// sheet: growth leaves it out (it lies within the layer, so close to the surface made).
#pragma once

#include <cstdint>
#include <vector>

#include "common/vec3.hpp"
#include "grid/hash_grid.hpp"

namespace g2s {

// Eigen-decomposition of the symmetric 3x3 matrix m (row-major, m[3*i+j]) by cyclic Jacobi
// rotations: eigenvalues ascending in values, unit eigenvectors in vectors (vectors[k] belongs
// to values[k]). Exact to rounding for every finite input.
void symmetric_eigen(const double m[9], double values[3], Vec3 vectors[3]);

// The neighbours a point's surface is fitted to: the fit spans about 2.8 spacings around the
// point, several times a layer of about the spacing, with 18 degrees of freedom left for the
// residuals' spread.
inline constexpr int kSheetNeighbours = 24;

// Per point of the grid (in grid order), 1 where it lies off the sheet as described above, else
// 0. Deterministic (depends on the grid alone); runs in parallel over the points.
std::vector<std::uint8_t> off_sheet_points(const HashGrid& grid);

}  // namespace g2s
