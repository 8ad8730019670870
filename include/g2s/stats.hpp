// Defect measurement of any triangle mesh (src/stats/), as defined in docs/algorithm.md §9.
// Linear time in the number of triangles (hash tables and a vertex->triangle table, no sorting),
// deterministic; the self-intersection test runs in parallel.
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
  // Self-intersections: pairs of kept triangles whose closed triangles meet other than in the
  // corners or the edge they share (folded flat onto a shared edge, or crossing elsewhere).
  std::uint64_t crossing_pairs = 0;
  std::uint64_t crossing_pairs_no_shared_vertex = 0;  // of those, pairs with no vertex in common
  std::uint64_t crossing_triangles = 0;               // triangles in at least one crossing pair
  // False where the crossings were not counted (g2s mesh's summary, counted as the mesh streams
  // out): the three counts above are then left out of the text and JSON forms.
  bool has_crossings = true;
  // With input points: share of them whose coordinates, rounded to float, are a vertex.
  bool has_coverage = false;
  std::uint64_t input_points = 0;
  std::uint64_t covered_points = 0;
  double coverage = 0.0;
  // With input points, also how far the points that are not vertices lie from the mesh: the
  // distance to the nearest kept triangle, in units of the cloud's spacing (the median distance
  // from a point to its nearest neighbour at another position, over up to 65,536 of the points).
  // has_distances is false when the mesh has no kept triangle or the spacing is 0.
  bool has_distances = false;
  double spacing = 0.0;                 // in the cloud's units
  std::uint64_t off_mesh_points = 0;    // input points that are not vertices (finite ones)
  std::uint64_t off_mesh_within_1 = 0;  // of them, at most 1 spacing from the mesh
  std::uint64_t off_mesh_within_2 = 0;  // at most 2 spacings (including the above)
  std::uint64_t off_mesh_within_4 = 0;  // at most 4 spacings
  std::uint64_t off_mesh_beyond_4 = 0;  // more than 4 spacings
  double off_mesh_median = 0.0;         // quantiles of the distance, in spacings
  double off_mesh_p90 = 0.0;
  double off_mesh_p99 = 0.0;
  double off_mesh_max = 0.0;
  // Of the points off the mesh, those with fewer than two other input points (at other
  // positions) within 2 spacings: no triangle with sides of at most 2 spacings can have them as
  // a corner, so they are outliers, not surface left out. surface_coverage is covered_points
  // over input_points less those (equal to coverage when none is left out).
  std::uint64_t off_mesh_isolated = 0;
  std::uint64_t off_mesh_far_not_isolated = 0;  // not isolated, yet more than 2 spacings off
  double surface_coverage = 0.0;
};

// Measures a mesh, in this order:
// - Welding: corners are merged by exact equality of their three double coordinates (-0.0 equals
//   0.0), so a mesh read from STL and the same mesh held indexed give the same numbers.
// - Degenerate triangles (two equal welded corners, or three exactly collinear corners, decided
//   by exact predicates) are counted and then left out of every other count except `triangles`:
//   their corners count as vertices, join components and cover points only through other triangles.
// - Duplicates (a later triangle with the vertex set of an earlier one, either orientation) are
//   counted; the first copy in input order is kept and the others are left out of the edge,
//   vertex and fan counts. So a reversed copy listed first can turn into orientation conflicts.
// - Edges, fans, holes and components are then counted on what is left, as in MeshStats.
// - Crossings: every pair of kept triangles (not degenerate, not a duplicate copy, finite
//   coordinates) is tested exactly, without tolerance: two triangles cross when the closed
//   triangles share a point that is not a corner or edge they share (docs/algorithm.md, "Mesh
//   statistics"). Candidate pairs come from a grid of the triangles' boxes; this part runs in
//   parallel in the caller's TBB arena, with the same counts for any thread count.
// - Coverage, when input_points is given: an input point is covered when a vertex of a kept
//   triangle has its coordinates. Where every such vertex lies on floats (as in any STL), both
//   are rounded to float first, so that an STL of a double-precision cloud still covers it;
//   otherwise they are compared exactly (at georeferenced coordinates float's step is half a
//   metre, and a double mesh's points that far apart are not one). Every given point
//   counts, duplicates included; coverage is 0 for an empty cloud. The points not covered are
//   then measured against the mesh (see has_distances), in parallel.
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
