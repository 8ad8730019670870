// The Gabriel walk (ALGORITHM.md §1, §4): among the candidate points for front edge ab, the one
// whose smallest circumscribing ball with a and b holds no other candidate. Start at the
// candidate nearest the edge midpoint, move to the candidate deepest inside the current ball,
// stop when none is inside. Co-circular ties go to the smaller index, so the answer does not
// depend on the candidates' order. Its own file so that it can be measured alone (bench/).
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
  if (candidates.empty()) return kNoIndex;
  std::size_t start = 0;
  double best = 0;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const double d2 = norm2(grid.position(candidates[k]) - mid);
    if (k == 0 || d2 < best || (d2 == best && candidates[k] < candidates[start])) {
      start = k, best = d2;
    }
  }
  Index p = candidates[start];
  for (std::size_t step = 0; step <= candidates.size(); ++step) {
    Ball ball;
    if (!circumball(a, b, grid.position(p), ball)) {
      // (Nearly) on the line ab: no triangle. Walk on among the others.
      candidates.erase(std::find(candidates.begin(), candidates.end(), p));
      if (candidates.empty()) return kNoIndex;
      p = candidates.front();
      continue;
    }
    const double tol = 1e-6 * ball.radius2;
    Index next = kNoIndex;
    double deepest = 0;
    for (Index q : candidates) {
      if (q == p) continue;
      const double depth = norm2(grid.position(q) - ball.centre) - ball.radius2;
      const bool inside = depth < -tol || (depth <= tol && q < p);
      if (inside && (next == kNoIndex || depth < deepest)) next = q, deepest = depth;
    }
    if (next == kNoIndex) return p;
    p = next;
  }
  return p;
}

}  // namespace g2s
