// Per-point tangent planes for growing one sheet through thick or layered regions
// (docs/algorithm.md, "One sheet through thick layers"). Where overlapping scans or noise make
// the points a layer thicker than their spacing, the Gabriel point of a front edge is often a
// point on the layer's other face, and the triangle to it stands across the layer: the front
// folds between the faces and leaves holes and crossings. The plane fitted (PCA) to a point's
// nearest neighbours lies along the layer; a candidate triangle that stands steeper to the
// planes of its edge's ends than the bound, beyond what the fit can tell, is not made, so growth
// stays in one sheet and points off it stay unused. Where the neighbourhood is not flat (sharp
// edges, corners, thin parts), the fit's own uncertainty widens the bound past a right angle and
// the test never refuses.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <utility>
#include <vector>

#include "common/vec3.hpp"
#include "grid/hash_grid.hpp"

namespace g2s {

// The neighbours a plane is fitted to: enough that the fit spans a few spacings, well beyond a
// layer of a few spacings' thickness, and that noise averages out.
inline constexpr int kTangentNeighbours = 24;

// A fitted plane: unit normal, and the test's threshold: a triangle whose unit normal m has
// |m . normal| < cos_limit stands too steep to it. cos_limit <= 0: the plane never refuses.
struct TangentPlane {
  Vec3f normal;
  float cos_limit;
  float off_middle =
      0;  // |offset from the fitted plane| / (layer sigma), where the layer is thick; else 0
};

// The eigenvalues (ascending) and the unit eigenvector of the smallest of the symmetric 3x3
// matrix m (row-major, m[3*i+j]). Cyclic Jacobi rotations: exact to rounding for every input.
void smallest_eigen(const double m[9], double values[3], Vec3& vector);

// The plane fitted to the k nearest points of the grid around `centre` (itself among them),
// with the bound `bound_rad`: cos_limit = cos(bound + atan(sqrt(l0 / l1))), l0 <= l1 the two
// smallest eigenvalues of the neighbours' covariance (0 when that angle reaches a right angle or
// fewer than 3 neighbours are found within 8 spacings). `near` is scratch.
TangentPlane fit_tangent_plane(const HashGrid& grid, std::uint32_t centre, int k, double bound_rad,
                               std::vector<std::pair<double, std::uint32_t>>& near);

// The planes of a grid's points, each fitted when first asked for (most points are, once).
class TangentPlanes {
 public:
  TangentPlanes(const HashGrid& grid, double bound_rad)
      : grid_(grid),
        bound_rad_(bound_rad),
        planes_(bound_rad > 0 || std::getenv("G2S_MIDDLE") ? grid.size() : 0) {
    for (TangentPlane& p : planes_) p.cos_limit = kUnknown;
  }

  bool enabled() const { return !planes_.empty(); }

  const TangentPlane& at(std::uint32_t i) {
    TangentPlane& p = planes_[i];
    if (p.cos_limit == kUnknown) p = fit_tangent_plane(grid_, i, k_, bound_rad_, near_);
    return p;
  }

  // Whether a triangle with (not necessarily unit) normal w stands too steep to plane p.
  static bool steep(const TangentPlane& p, const Vec3& w) {
    if (p.cos_limit <= 0) return false;
    const double along = dot(w, Vec3(p.normal));
    const double limit = static_cast<double>(p.cos_limit);
    return along * along < limit * limit * norm2(w);
  }

 private:
  static constexpr float kUnknown = 2.0f;
  const HashGrid& grid_;
  const double bound_rad_;
  int k_ = std::getenv("G2S_SHEET_K") ? std::atoi(std::getenv("G2S_SHEET_K")) : kTangentNeighbours;
  std::vector<TangentPlane> planes_;
  std::vector<std::pair<double, std::uint32_t>> near_;
};

}  // namespace g2s
