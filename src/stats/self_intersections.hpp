// Self-intersections of a welded mesh for compute_stats (src/stats/self_intersections.cpp).
#pragma once

#include <cstdint>
#include <span>

#include "g2s/types.hpp"

namespace g2s::stats {

struct CrossingCounts {
  std::uint64_t pairs = 0;                   // pairs of triangles that cross
  std::uint64_t pairs_no_shared_vertex = 0;  // of them, pairs with no vertex in common
  std::uint64_t triangles = 0;               // triangles in at least one crossing pair
};

// Counts the pairs of triangles for which triangles_cross (common/triangle_intersection.hpp)
// holds. triangles: welded vertex ids, non-degenerate (not exactly collinear); entries whose
// first id is kNoIndex (duplicates set aside) are skipped, as are triangles with a non-finite
// coordinate. Welded vertex w lies at xyz[3 * rep[w] ..]; equal ids are equal positions and
// different ids different positions. Runs in parallel in the caller's TBB arena; the counts do not
// depend on the thread count.
CrossingCounts count_crossings(std::span<const Triangle> triangles, const double* xyz,
                               std::span<const Index> rep);

}  // namespace g2s::stats
