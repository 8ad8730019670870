// The G2S mesher's options and counts (src/grid, src/grow, src/cleanup): Gabriel 2-simplex mesh
// growing with the discrete priority queue and non-manifold vertex removal of Di Angelo &
// Giaccari (2011), docs/algorithm.md. The mesher runs inside the tiled pipeline
// (include/g2s/pipeline.hpp: mesh_cloud for a cloud in memory, mesh_tiles for a tile source).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "g2s/types.hpp"

namespace g2s {

struct MeshOptions {
  // Search radius levels (docs/algorithm.md §4): the front search ball has radius
  // step * max(|ab|, spacing / 2) (at most max_radius spacings), tried in increasing order.
  std::vector<double> radius_steps{1.0, 1.5, 2.0, 3.0};
  // Flatness levels m: the fold angle beta in [0, max_fold_deg] quantised into m levels.
  int flatness_levels = 4;
  // A new triangle whose normal turns more than this from its front neighbour's is a fold.
  double max_fold_deg = 135.0;
  // No search ball is larger than this many spacings (the median nearest-neighbour distance; in
  // the tiled pipeline the whole cloud's, or a tile's where provably larger): fronts do not
  // bridge voids, and a query never scans a large part of the cloud.
  double max_radius = 6.0;
  // Seed search ball radius, in nearest-neighbour edge lengths (docs/algorithm.md §2).
  double seed_ball = 2.5;
  // Once growth is over, close gaps of three open edges with a triangle where the Point-Edge
  // Map, the orientation groups and the fold limit allow it (docs/algorithm.md §3); off: the
  // paper's G2S alone.
  bool close_gaps = true;
  // Once growth is over, close every hole whose boundary loop has at most this many edges with
  // triangles over the loop's own points, where the result stays manifold, consistently
  // oriented and free of crossings (docs/algorithm.md, "Hole filling"). Small objects are
  // closed too: a piece using every point of the run, at most one of them inside it, has its
  // outer border filled, and a piece whose only border is such a loop is capped by a fan to a
  // point no triangle uses (a tetrahedron's four points give its four faces; "Small objects
  // closed"). 0: none. At most
  // kMaxHoleEdges counts (a loop of n edges costs O(n^3) memory and O(n^4) time to fill).
  int max_hole_edges = 30;
  static constexpr int kMaxHoleEdges = 100;
  // A hole that cannot be filled over its own points (most often because the surface around it
  // folds over it) may be widened by up to this many rings of triangles around it and filled in
  // their place (after r rings its border may have max_hole_edges + 6r edges, at most
  // kMaxHoleEdges), leaving out the points inside that lie within 3 spacings of the surface
  // (docs/algorithm.md, "Hole filling"); a hole still open, when only triangles of its corners'
  // fans folded over it refuse its filling, is widened by those and the ring across its edges
  // ("Folds over a hole"); scraps (pieces with no interior point within 3 spacings
  // of another piece) are removed too, when holes are filled at all (max_hole_edges >= 3). 0: every
  // hole is filled over its own loop or not at all, and no point is left out. At most
  // kMaxHoleRings.
  int max_hole_rings = 3;
  static constexpr int kMaxHoleRings = 10;
  // Orient each closed component outward (open, mostly horizontal ones up; see
  // docs/algorithm.md §6).
  bool orient = true;
  // Called now and then while growing with (points used so far, points in total); may be empty.
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

// Counts from one run, for the CLI summary, --json and the tests.
struct MeshReport {
  std::uint64_t points = 0;             // points given
  std::uint64_t duplicates_merged = 0;  // exact duplicates (and twins' near-copies) left out
  std::uint64_t seeds = 0;              // seed triangles (front components) grown
  std::uint64_t triangles_grown = 0;    // before the non-manifold pass
  std::uint64_t triangles_removed = 0;  // by the non-manifold pass
  std::uint64_t non_manifold_vertices_fixed = 0;
  std::uint64_t components_flipped = 0;  // components reoriented at the end
  double spacing = 0.0;                  // estimated median nearest-neighbour distance
  double seconds_grid = 0.0;
  double seconds_grow = 0.0;
  // Of seconds_grow: the finishing of the surface once growth is over (hole filling, the fan
  // clean-up between its rounds, scraps and caps; docs/algorithm.md, "Hole filling"), which
  // --max-hole-edges 0 skips.
  double seconds_finish = 0.0;
  double seconds_cleanup = 0.0;
};

}  // namespace g2s
