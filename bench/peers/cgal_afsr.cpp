// Peer driver: CGAL's Advancing Front Surface Reconstruction (Cohen-Steiner & Da, 2004) as the
// CGAL manual's example reconstruction_fct.cpp calls it: the free function over the raw points,
// default parameters (radius_ratio_bound 5, beta pi/6). Usage and output: peer_driver.hpp;
// parameters and sources: bench/peers/README.md.
#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <array>
#include <iterator>
#include <utility>
#include <vector>

#include "peer_driver.hpp"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Facet = std::array<std::size_t, 3>;

g2s::IndexedMesh reconstruct(g2s::PointCloud& cloud) {
  std::vector<Kernel::Point_3> points;
  points.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    points.emplace_back(cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]);
  }
  std::vector<Facet> facets;
  CGAL::advancing_front_surface_reconstruction(points.begin(), points.end(),
                                               std::back_inserter(facets));
  g2s::IndexedMesh mesh;
  mesh.triangles.reserve(facets.size());
  for (const Facet& f : facets) {  // indices into the input range, so into cloud.xyz
    mesh.triangles.push_back({static_cast<g2s::Index>(f[0]), static_cast<g2s::Index>(f[1]),
                              static_cast<g2s::Index>(f[2])});
  }
  mesh.xyz = std::move(cloud.xyz);
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  return g2s::peers::run_peer(argc, argv, "cgal-afsr", reconstruct);
}
