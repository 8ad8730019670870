// Triangulating a hole: the least-area triangulation of a closed boundary loop over its own
// points (no new vertex, so the mesh still interpolates the cloud). The grower fills small
// holes with it once growth is over (docs/algorithm.md, "Hole filling").
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s::detail {

// Working arrays of triangulate_loop, kept between calls so that filling allocates once.
struct HoleScratch {
  std::vector<double> cost;
  std::vector<std::uint16_t> split;
  std::vector<std::size_t> stack;
};

inline double triangle_area(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  return 0.5 * norm(cross(Vec3(b) - Vec3(a), Vec3(c) - Vec3(a)));
}

// Inputs: points; loop, the hole's corners in the order the filling triangles traverse them
// (each filling triangle is counter-clockwise along it; at most 65,535 corners); chord_ok(i, j),
// for loop positions i < j that are not neighbours on the loop, whether the edge
// loop[i]-loop[j] may be made (false where the mesh has that edge already); scratch space.
// Output: appends loop.size() - 2 triangles to `out` and returns true, or returns false (out
// unchanged) when every triangulation needs a forbidden chord or a degenerate triangle.
template <class ChordOk>
bool triangulate_loop(std::span<const Vec3f> points, std::span<const Index> loop,
                      ChordOk&& chord_ok, HoleScratch& scratch, std::vector<Triangle>& out) {
  const std::size_t n = loop.size();
  if (n < 3) return false;
  constexpr double kNone = 1e300;
  // cost[i*n + j]: least area of the polygon loop[i..j] closed by chord i-j (Barequet & Sharir's
  // dynamic programme, O(n^3)); split: the apex k of the triangle on chord i-j.
  scratch.cost.assign(n * n, kNone);
  scratch.split.assign(n * n, 0);
  for (std::size_t i = 0; i + 1 < n; ++i) scratch.cost[i * n + i + 1] = 0;
  for (std::size_t width = 2; width < n; ++width) {
    for (std::size_t i = 0; i + width < n; ++i) {
      const std::size_t j = i + width;
      // The chord i-j is a loop edge only for (0, n-1).
      if (!(i == 0 && j == n - 1) && !chord_ok(i, j)) continue;
      double best = kNone;
      std::uint16_t best_k = 0;
      for (std::size_t k = i + 1; k < j; ++k) {
        const double left = scratch.cost[i * n + k], right = scratch.cost[k * n + j];
        if (left >= kNone || right >= kNone) continue;
        const double area = triangle_area(points[loop[i]], points[loop[k]], points[loop[j]]);
        if (!(area > 0)) continue;
        if (left + right + area < best) {
          best = left + right + area;
          best_k = static_cast<std::uint16_t>(k);
        }
      }
      scratch.cost[i * n + j] = best;
      scratch.split[i * n + j] = best_k;
    }
  }
  if (scratch.cost[n - 1] >= kNone) return false;
  // Unwind the splits: (i, k, j) is counter-clockwise along the loop's order.
  std::vector<std::size_t>& stack = scratch.stack;
  stack.assign({0, n - 1});
  while (!stack.empty()) {
    const std::size_t j = stack.back();
    stack.pop_back();
    const std::size_t i = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const std::size_t k = scratch.split[i * n + j];
    out.push_back({loop[i], loop[k], loop[j]});
    stack.insert(stack.end(), {i, k, k, j});
  }
  return true;
}

}  // namespace g2s::detail
