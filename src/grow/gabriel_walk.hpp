// The Gabriel walk (ALGORITHM.md §1, §4): among the candidate points for front edge ab, the one
// whose smallest circumscribing ball with a and b holds no other candidate. Start at the
// candidate nearest the edge midpoint, move to the candidate deepest inside the current ball,
// stop when none is inside. Every tie (equally near, equally deep, co-circular) goes to the
// smaller index, so the answer does not depend on the candidates' order, and so not on the order
// in which the grid visits its cells. Its own file so that it can be measured alone (bench/).
#pragma once

#include <algorithm>
#include <vector>

#include "common/vec3.hpp"
#include "grid/hash_grid.hpp"

namespace g2s {

// Candidates on (or nearly on) the line ab are dropped from `candidates` as met; kNoIndex when
// none is left.
inline Index gabriel_walk(const HashGrid& grid, const Vec3& a, const Vec3& b, const Vec3& mid,
                          std::vector<Index>& candidates) {
  // The candidate nearest the edge midpoint.
  const auto nearest = [&] {
    Index start = kNoIndex;
    double best = 0;
    for (Index q : candidates) {
      const double d2 = norm2(grid.position(q) - mid);
      if (start == kNoIndex || d2 < best || (d2 == best && q < start)) start = q, best = d2;
    }
    return start;
  };
  if (candidates.empty()) return kNoIndex;
  Index p = nearest();
  for (std::size_t step = 0; step <= candidates.size(); ++step) {
    Ball ball;
    if (!circumball(a, b, grid.position(p), ball)) {
      // (Nearly) on the line ab: no triangle. Walk on among the others, from the nearest.
      candidates.erase(std::find(candidates.begin(), candidates.end(), p));
      if (candidates.empty()) return kNoIndex;
      p = nearest();
      continue;
    }
    const double tol = 1e-6 * ball.radius2;
    Index next = kNoIndex;
    double deepest = 0;
    for (Index q : candidates) {
      if (q == p) continue;
      const double depth = norm2(grid.position(q) - ball.centre) - ball.radius2;
      const bool inside = depth < -tol || (depth <= tol && q < p);
      if (inside && (next == kNoIndex || depth < deepest || (depth == deepest && q < next))) {
        next = q, deepest = depth;
      }
    }
    if (next == kNoIndex) return p;
    p = next;
  }
  return p;
}

}  // namespace g2s
