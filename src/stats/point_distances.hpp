// Distances from the input points that are not mesh vertices to the mesh, for compute_stats
// (src/stats/point_distances.cpp).
#pragma once

#include <cstdint>
#include <span>

#include "g2s/stats.hpp"
#include "g2s/types.hpp"

namespace g2s::stats {

// Fills stats' off-mesh fields: the cloud's spacing (median nearest-distinct-neighbour distance
// of up to 65,536 of its points, every k-th) and the distribution of the distances from the
// points off_mesh (indices into cloud) to the nearest kept triangle, in spacings. triangles and
// xyz/rep as for count_crossings. Sets stats.has_distances unless the mesh has no usable triangle
// or the spacing is 0.
void measure_point_distances(std::span<const Triangle> triangles, const double* xyz,
                             std::span<const Index> rep, const PointCloud& cloud,
                             std::span<const std::uint64_t> off_mesh, MeshStats& stats);

}  // namespace g2s::stats
