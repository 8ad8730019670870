// Post-processing of a grown mesh: non-manifold vertex removal (docs/algorithm.md §5) and the
// orientation of each component, both as the pipeline applies them while the mesh is built.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "common/union_find.hpp"
#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s {

struct NonManifoldReport {
  std::uint64_t vertices_fixed = 0;
  std::uint64_t triangles_removed = 0;
  // Vertices a deletion may have split but which could not be judged (mark_non_manifold_fans).
  std::uint64_t vertices_unjudged = 0;
};

// Of each vertex's fans (its triangles linked across the edges they share at it) keeps one, the
// closed one (type I) or the largest (type II), and marks the others' triangles for deletion in
// `dead` (one flag per triangle, set to 1); triangles must have no non-manifold edge. It works on
// a mesh still being built (the grower's, a tile's, the stitcher's live triangles): only
// `suspects` (where the grower started a second fan) and the vertices a deletion may split are
// examined, and of those only vertices whose star is complete and whole (finished[v] == 1) are
// judged; a deletion that may split the fan of an unfinished vertex (0) puts that vertex in
// `deferred`, to be judged when it is finished, and one of a vertex whose star is no longer
// whole (2) is counted as unjudged. An empty `finished` means every vertex is judged.
NonManifoldReport mark_non_manifold_fans(std::span<const Triangle> triangles,
                                         std::size_t vertex_count, std::span<const Index> suspects,
                                         std::span<const std::uint8_t> finished,
                                         std::vector<std::uint8_t>& dead,
                                         std::vector<Index>& deferred);

// Per orientation group, sums over its triangles as stored (not yet flipped), enough to orient
// the component at the end without the triangles: with positions taken from a fixed origin, a
// component's volume about its centroid c is sum(det) - c . sum(normal).
struct GroupSums {
  double det = 0;          // sum of det(a, b, c)
  Vec3 normal{0, 0, 0};    // sum of (b - a) x (c - a)
  Vec3 centroid{0, 0, 0};  // sum of the corners
  double corners = 0;
  std::uint64_t edge_keys = 0;  // XOR of the edge keys: 0 when the component is closed
};

// The flips that orient a mesh given as orientation groups: flip[g] reverses group g. Groups
// joined in `groups` form one component; its parity makes it consistent, and with `orient` the
// component then faces outward if closed (positive signed volume about its centroid), up (+z)
// if open with a mean normal mostly vertical (aerial scans), else away from its centroid.
// Counts the components reversed.
std::vector<std::uint8_t> group_flips(ParityUnionFind& groups, std::span<const GroupSums> sums,
                                      bool orient, std::uint64_t& flipped);

// A well-mixed 64-bit key of an undirected edge (splitmix64's finaliser): XORed over a closed
// component's triangles, every edge cancels.
inline std::uint64_t edge_key(Index u, Index v) {
  std::uint64_t x = u < v ? std::uint64_t{u} << 32 | v : std::uint64_t{v} << 32 | u;
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace g2s
