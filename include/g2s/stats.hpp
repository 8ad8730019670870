// Defect measurement of any triangle mesh (src/stats/), as defined in docs/algorithm.md §9.
// Linear time in the number of triangles (hash tables and a vertex->triangle table, no sorting),
// single-threaded and deterministic.
#pragma once

#include <cstdint>
#include <string>

#include "g2s/types.hpp"

namespace g2s {

struct MeshStats {
  std::uint64_t triangles = 0;              // as given, before anything is left out
  std::uint64_t vertices = 0;               // distinct positions used by kept triangles
  std::uint64_t degenerate_triangles = 0;   // two equal corners or three collinear corners
  std::uint64_t duplicate_triangles = 0;    // extra copies of a vertex set, either orientation
  std::uint64_t non_manifold_edges = 0;     // edges in more than 2 triangles
  std::uint64_t boundary_edges = 0;         // edges in exactly 1 triangle
  std::uint64_t orientation_conflicts = 0;  // 2-triangle edges traversed the same way by both
  std::uint64_t non_manifold_vertices = 0;  // more than one fan (type I + type II)
  std::uint64_t non_manifold_vertices_type1 = 0;  // at least one fan closed
  std::uint64_t non_manifold_vertices_type2 = 0;  // all fans open
  std::uint64_t holes = 0;                        // cycle rank of the boundary-edge graph
  std::uint64_t components = 0;                   // triangles sharing a vertex are connected
  // With input points: share of them whose coordinates, rounded to float, are a vertex.
  bool has_coverage = false;
  std::uint64_t input_points = 0;
  std::uint64_t covered_points = 0;
  double coverage = 0.0;
};

// Measures a mesh, in this order:
// - Welding: corners are merged by exact equality of their three double coordinates (-0.0 equals
//   0.0), so a mesh read from STL and the same mesh held indexed give the same numbers.
// - Degenerate triangles (two equal welded corners, or a cross product of exactly zero computed
//   in double) are counted and then left out of every other count except `triangles`: their
//   corners count as vertices, join components and cover points only through other triangles.
// - Duplicates (a later triangle with the vertex set of an earlier one, either orientation) are
//   counted; the first copy in input order is kept and the others are left out of the edge,
//   vertex and fan counts. So a reversed copy listed first can turn into orientation conflicts.
// - Edges, fans, holes and components are then counted on what is left, as in MeshStats.
// - Coverage, when input_points is given: an input point is covered when a vertex of a kept
//   triangle has the same coordinates after both are rounded to float, because STL stores
//   float32 and an STL mesh of a double-precision cloud must still cover it. Every given point
//   counts, duplicates included; coverage is 0 for an empty cloud.
// Throws Error(bad_input) when a triangle indexes a vertex past the end of mesh.xyz.
MeshStats compute_stats(const IndexedMesh& mesh, const PointCloud* input_points = nullptr);

// The triangles of the largest connected piece of mesh (most triangles; triangles sharing a
// vertex index are connected; of equal pieces, the one whose first triangle comes first), in
// input order, with all of mesh.xyz. Index-based: weld first (read_mesh does for STL) when
// corners may repeat a position under different indices. Throws Error(bad_input) when a
// triangle indexes a vertex past the end of mesh.xyz.
IndexedMesh largest_component(const IndexedMesh& mesh);

std::string stats_to_json(const MeshStats& stats);  // one JSON object, stable key order
std::string stats_to_text(const MeshStats& stats);  // aligned "name  value" lines for people

}  // namespace g2s
