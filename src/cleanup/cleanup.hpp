// Post-processing of a grown mesh: non-manifold vertex removal (ALGORITHM.md §6) and the
// orientation of each component.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s {

struct NonManifoldReport {
  std::uint64_t vertices_fixed = 0;
  std::uint64_t triangles_removed = 0;
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

}  // namespace g2s
