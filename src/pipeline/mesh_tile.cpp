// The in-memory mesher, stage by stage: hash grid (src/grid) -> G2S growth (src/grow) ->
// non-manifold removal and orientation (src/cleanup) -> triangles in global ids.
#include <chrono>
#include <cmath>

#include "cleanup/cleanup.hpp"
#include "g2s/error.hpp"
#include "g2s/mesher.hpp"
#include "grid/hash_grid.hpp"
#include "grow/grower.hpp"
#include "pipeline/tile_geometry.hpp"

namespace g2s {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TileMesh mesh_tile(std::span<const float> xyz, std::span<const Index> ids,
                   const MeshOptions& options) {
  if (xyz.size() % 3 != 0) throw Error(Exit::failure, "mesh_tile: xyz length not a multiple of 3");
  if (!ids.empty() && ids.size() * 3 != xyz.size()) {
    throw Error(Exit::failure, "mesh_tile: ids and xyz differ in length");
  }
  if (options.radius_steps.empty() || options.flatness_levels < 1) {
    throw Error(Exit::usage, "mesh options: need at least one radius step and flatness level");
  }
  TileMesh out;
  out.report.points = xyz.size() / 3;

  auto t0 = std::chrono::steady_clock::now();
  const HashGrid grid(xyz, ids);
  out.report.duplicates_merged = grid.duplicates_merged();
  out.report.spacing = grid.spacing();
  out.report.seconds_grid = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  GrowResult grown = grow_mesh(grid, options);
  out.report.seeds = grown.seeds;
  out.report.triangles_grown = grown.triangles.size();
  out.report.seconds_grow = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  std::vector<Triangle>& triangles = grown.triangles;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (grown.flip[t]) std::swap(triangles[t][1], triangles[t][2]);
  }
  const NonManifoldReport nm =
      remove_non_manifold_vertices_at(triangles, grid.size(), grown.second_fans);
  out.report.triangles_removed = nm.triangles_removed;
  out.report.non_manifold_vertices_fixed = nm.vertices_fixed;
  out.open_edges = open_edges(triangles, grid.size());
  if (options.orient) {
    out.report.components_flipped = orient_components(triangles, grid.points(), out.open_edges);
  }
  for (Triangle& t : triangles) {
    for (Index& v : t) v = grid.id(v);
  }
  for (auto& e : out.open_edges) {
    for (Index& v : e) v = grid.id(v);
  }
  out.triangles = std::move(triangles);
  out.report.seconds_cleanup = seconds_since(t0);
  return out;
}

TileMesh mesh_cloud(const PointCloud& cloud, const MeshOptions& options) {
  const std::size_t n = cloud.size();
  if (n > kNoIndex) throw Error(Exit::bad_input, "cloud has more than 4,294,967,295 points");
  // Local frame around the bounding-box centre, computed in double: floats keep their precision
  // even for georeferenced coordinates around 1e7.
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = hi[a] = n ? cloud.xyz[a] : 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], cloud.xyz[3 * i + a]);
      hi[a] = std::max(hi[a], cloud.xyz[3 * i + a]);
    }
  }
  std::vector<float> local(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      local[3 * i + a] = static_cast<float>(cloud.xyz[3 * i + a] - frame_origin(lo[a], hi[a]));
    }
  }
  return mesh_tile(local, {}, options);
}

}  // namespace g2s
