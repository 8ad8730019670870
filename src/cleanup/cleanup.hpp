// Post-processing of a grown mesh: non-manifold vertex removal (docs/algorithm.md §5) and the
// orientation of each component.
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

// Deletes triangles until every vertex's triangles form a single fan: of a vertex's fans it keeps
// the closed one (type I) or the largest (type II). Triangles must have no non-manifold edge.
// Removed triangles are erased from `triangles`; the order of the rest is kept.
NonManifoldReport remove_non_manifold_vertices(std::vector<Triangle>& triangles,
                                               std::size_t vertex_count);

// The same, when only `suspects` can have more than one fan (the grower knows where it started a
// second fan): vertices are examined only there and where deletions split fans.
NonManifoldReport remove_non_manifold_vertices_at(std::vector<Triangle>& triangles,
                                                  std::size_t vertex_count,
                                                  std::span<const Index> suspects);

// The same on a mesh still being built (the stitcher's live triangles): triangles to delete are
// marked in `dead` (one flag per triangle, set to 1) rather than erased, and only vertices whose
// star is complete and whole (finished[v] == 1) are judged; a deletion that may split the fan
// of an unfinished vertex (0) puts that vertex in `deferred`, to be judged when it is finished,
// and one of a vertex whose star is no longer whole (2) is counted as unjudged. An empty
// `finished` means every vertex is judged.
NonManifoldReport mark_non_manifold_fans(std::span<const Triangle> triangles,
                                         std::size_t vertex_count, std::span<const Index> suspects,
                                         std::span<const std::uint8_t> finished,
                                         std::vector<std::uint8_t>& dead,
                                         std::vector<Index>& deferred);

// Edges used by exactly one triangle, as that triangle traverses them.
std::vector<std::array<Index, 2>> open_edges(const std::vector<Triangle>& triangles,
                                             std::size_t vertex_count);

// Flips whole components so that closed ones face outward (positive signed volume), and open
// ones whose mean normal is mostly vertical face up (+z, aerial scans), the others away from
// their centroid. Triangles must be consistently oriented within a component and have no
// non-manifold vertex (so components joined at a vertex are joined along edges too).
// `open`: the mesh's open edges (open_edges()), reversed where their component is flipped.
// Returns the number of components flipped.
std::uint64_t orient_components(std::vector<Triangle>& triangles, std::span<const Vec3f> positions,
                                std::vector<std::array<Index, 2>>& open);

// The same, telling closed components from open ones without an edge map (an XOR of edge keys).
std::uint64_t orient_components(std::vector<Triangle>& triangles, std::span<const Vec3f> positions);

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
// component then faces as orient_components() would have it. Counts the components reversed.
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
