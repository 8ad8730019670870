// Stratified sampling of the analytic shapes behind g2s::make_synthetic_cloud: each surface is
// cut into patches, each patch into rows of near-square cells (one jittered point per cell), so
// the samples look like a good scanner's: even spacing, no clumps, exact point counts.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "g2s/synth.hpp"

namespace g2s::synth {

// Half-width of the jitter inside a cell, in cells: a point lies within +-kJitter of its cell's
// centre along each parameter, so neighbours in a row stay at least 1 - 2 * kJitter cells apart
// and ties (four points on a circle, as in a perfect grid) are broken. 0.2 keeps the mean
// nearest-neighbour distance near 0.85 spacing; a full-cell jitter would allow near-duplicates.
inline constexpr double kJitter = 0.2;

// One patch of a surface, sampled row by row. A row is a strip of the parameter domain whose
// points are spread over near-square cells; rows hold point counts proportional to their area.
struct Patch {
  enum class Kind {
    rectangle,     // origin + s * edge_u + v * edge_v; rows along edge_u, v in row_edge
    height_field,  // a rectangle in the xy plane lifted to z = terrain_height(x, y)
    sphere_rings,  // unit sphere, rows are bands between z = row_edge[j] and row_edge[j+1],
                   // density proportional to exp(density_k * z)
    torus_rings,   // torus, rows are bands of tube angle theta between row_edge[j] and [j+1]
  };
  Kind kind = Kind::rectangle;
  std::uint64_t first = 0;  // index of the patch's first point in the cloud
  std::array<double, 3> origin{}, edge_u{}, edge_v{};
  double density_k = 0.0;
  std::vector<std::uint64_t> row_start;  // rows + 1 offsets from `first`; back() = point count
  std::vector<double> row_edge;          // rows + 1 boundaries of the row parameter
};

struct Bounds {
  std::array<double, 3> lo, hi;
};

double shape_area(SynthShape shape);    // exact (terrain: converged quadrature)
Bounds shape_bounds(SynthShape shape);  // a box holding the surface; outliers fill it
double terrain_height(double x, double y);

// Builds the patches of a shape once, then generates any range of the cloud's points on demand.
// Points [0, surface) lie on the surface (plus noise); [surface, total) are the outliers.
class ShapeSampler {
 public:
  explicit ShapeSampler(const SynthOptions& options);  // options already validated

  std::uint64_t surface_points() const { return surface_; }
  std::uint64_t total_points() const { return total_; }
  double spacing() const { return spacing_; }

  // Writes points [begin, end) (end <= total_points()) as x, y, z floats into xyz[0, 3 * n).
  // Pure: the result depends only on the options and the indices, not on how ranges are cut.
  void generate(std::uint64_t begin, std::uint64_t end, float* xyz) const;

 private:
  std::vector<Patch> patches_;
  std::vector<std::uint64_t> patch_first_;  // patches + 1 entries; back() = surface_
  Bounds bounds_{};
  std::uint64_t surface_ = 0;
  std::uint64_t total_ = 0;
  double spacing_ = 0.0;
  double sigma_ = 0.0;
  std::uint64_t seed_ = 0;
};

}  // namespace g2s::synth
