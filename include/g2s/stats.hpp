// Defect measurement of any triangle mesh (src/stats/), as defined in ALGORITHM.md §8.
// Linear time in the number of triangles.
#pragma once

#include <cstdint>
#include <string>

#include "g2s/types.hpp"

namespace g2s {

struct MeshStats {
  std::uint64_t triangles = 0;               // as given, before anything is left out
  std::uint64_t vertices = 0;                // distinct positions used by triangles
  std::uint64_t degenerate_triangles = 0;    // two equal corners or three collinear corners
  std::uint64_t duplicate_triangles = 0;     // extra copies of a vertex set, either orientation
  std::uint64_t non_manifold_edges = 0;      // edges in more than 2 triangles
  std::uint64_t boundary_edges = 0;          // edges in exactly 1 triangle
  std::uint64_t orientation_conflicts = 0;   // 2-triangle edges traversed the same way by both
  std::uint64_t non_manifold_vertices = 0;   // more than one fan (type I + type II)
  std::uint64_t non_manifold_vertices_type1 = 0;  // at least one fan closed
  std::uint64_t non_manifold_vertices_type2 = 0;  // all fans open
  std::uint64_t holes = 0;                   // cycle rank of the boundary-edge graph
  std::uint64_t components = 0;              // triangles sharing a vertex are connected
  // With input points: share of input points whose exact coordinates are a mesh vertex.
  bool has_coverage = false;
  std::uint64_t input_points = 0;
  std::uint64_t covered_points = 0;
  double coverage = 0.0;
};

// Measures a mesh. Vertices are welded by exact coordinate equality first, so a mesh read from
// STL and the same mesh held indexed give the same numbers. Degenerate triangles are counted and
// then left out of every other count except `triangles`; duplicates are counted and left out of
// the edge counts.
MeshStats compute_stats(const IndexedMesh& mesh, const PointCloud* input_points = nullptr);

std::string stats_to_json(const MeshStats& stats);  // one JSON object, stable key order
std::string stats_to_text(const MeshStats& stats);  // aligned "name  value" lines for people

}  // namespace g2s
