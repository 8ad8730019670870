// The Gabriel walk (docs/algorithm.md §3): among the candidate points for front edge ab, the one
// whose smallest circumscribing ball with a and b holds no other candidate. Start at the
// candidate nearest the edge midpoint, move to the candidate deepest inside the current ball,
// stop when none is inside. Every tie (equally near, equally deep, co-circular) goes to the
// smaller index, so the answer does not depend on the candidates' order, and so not on the order
// in which the grid visits its cells. Its own file so that it can be measured alone (bench/).
#pragma once

#include <algorithm>
#include <vector>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s {

// A candidate: its grid index, its position and its squared distance to the edge midpoint
// (norm2(position - mid)), gathered once so that the walk's steps need not recompute them.
struct WalkPoint {
  Vec3 position;
  double dist2;
  Index index;
};

// Candidates on (or nearly on) the line ab are dropped from `candidates` as met; kNoIndex when
// none is left.
inline Index gabriel_walk(const Vec3& a, const Vec3& b, std::vector<WalkPoint>& candidates) {
  // The candidate nearest the edge midpoint.
  const auto nearest = [&] {
    const WalkPoint* start = &candidates.front();
    for (const WalkPoint& q : candidates) {
      if (q.dist2 < start->dist2 || (q.dist2 == start->dist2 && q.index < start->index)) {
        start = &q;
      }
    }
    return *start;
  };
  if (candidates.empty()) return kNoIndex;
  WalkPoint p = nearest();
  for (std::size_t step = 0; step <= candidates.size(); ++step) {
    Ball ball;
    if (!circumball(a, b, p.position, ball)) {
      // (Nearly) on the line ab: no triangle. Walk on among the others, from the nearest.
      candidates.erase(std::find_if(candidates.begin(), candidates.end(),
                                    [&](const WalkPoint& q) { return q.index == p.index; }));
      if (candidates.empty()) return kNoIndex;
      p = nearest();
      continue;
    }
    const double tol = 1e-6 * ball.radius2;
    const WalkPoint* next = nullptr;
    double deepest = 0;
    for (const WalkPoint& q : candidates) {
      if (q.index == p.index) continue;
      const double depth = norm2(q.position - ball.centre) - ball.radius2;
      const bool inside = depth < -tol || (depth <= tol && q.index < p.index);
      if (inside && (!next || depth < deepest || (depth == deepest && q.index < next->index))) {
        next = &q, deepest = depth;
      }
    }
    if (!next) return p.index;
    p = *next;
  }
  return p.index;
}

}  // namespace g2s
