// Triangulating a hole over the boundary loop's own points (no new vertex, so the mesh still
// interpolates the cloud). Of all triangulations, one whose sharpest fold (between two of its
// triangles, or between one of them and the mesh around the loop) is the gentlest, with a small
// area among those: the least-area triangulation alone folds a bent loop's filling back over
// itself, and the grower would then refuse it. The grower fills small holes with it once growth is
// over (docs/algorithm.md, "Hole filling").
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s::detail {

// Working arrays of triangulate_loop, kept between calls so that filling allocates once.
struct HoleScratch {
  // The best filling of the polygon loop[i..j] closed by chord i-j whose triangle on the chord
  // is (i, k, j): state (i, j, k).
  struct State {
    double fold_cos;  // the cosine of the sharpest fold inside (larger is gentler)
    double area;
    Vec3 normal;          // of triangle (i, k, j)
    std::uint16_t left;   // the apex on chord i-k (k == i + 1: a loop edge, none)
    std::uint16_t right;  // the apex on chord k-j
  };
  std::vector<State> states;
  // Per chord i-j: its apexes k with a filling, by decreasing fold_cos (count[i*n + j] of them
  // from by_fold[first[i*n + j]]), so that a parent's search can stop at the first that cannot
  // win.
  std::vector<std::uint16_t> by_fold;
  std::vector<std::uint16_t> count;
  std::vector<std::size_t> stack;
  // Per triangle (i, k, j), i < k < j: kUnasked, kAllowed or kRefused.
  std::vector<std::uint8_t> verdict;
  // Triangle (i, k, j), i < k < j, is entry first[i*n + j] + k - i - 1 of states, by_fold and
  // verdict: the n(n-1)(n-2)/6 triangles packed, a sixth of an n^3 array (a loop of 48 edges
  // needs 0.9 MB, not 5.6).
  std::vector<std::uint32_t> first;
  static constexpr std::uint8_t kUnasked = 0, kAllowed = 1, kRefused = 2;
};

inline double triangle_area(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  return 0.5 * norm(cross(Vec3(b) - Vec3(a), Vec3(c) - Vec3(a)));
}

// Inputs: points; loop, the hole's corners in the order the filling triangles traverse them
// (each filling triangle is counter-clockwise along it; at most 65,535 corners); around[i], the
// unit normal of the mesh triangle across loop edge loop[i]-loop[i+1] (i = n-1: across
// loop[n-1]-loop[0]), facing as the filling will; chord_ok(i, j), for loop positions i < j that
// are not neighbours on the loop, whether the edge loop[i]-loop[j] may be made (false where the
// mesh has that edge already); triangle_ok(i, k, j), whether the triangle on loop positions
// i < k < j may be made (asked at most once per triangle, after the cheaper conditions, and only
// about a triangle that would be chosen: see below); scratch space.
// Output: appends loop.size() - 2 triangles to `out` and returns the cosine of their sharpest
// fold (between two of them or with `around`), or returns nothing (out unchanged) when every
// triangulation needs a forbidden chord, a forbidden triangle or a degenerate one. The sharpest
// fold is the gentlest any triangulation has (exact); among those, the area is made small
// greedily.
// O(n^4) time at worst, far less as a rule (a parent's search stops at the first apex whose own
// fold cannot win), O(n^3) scratch: loops are short (the grower's limit is max_hole_edges).
// Every triangulation has a triangle on each loop edge, so a loop with an edge that no allowed
// triangle uses is given up first, after O(n^2) questions to triangle_ok instead of O(n^3).
// Then the states are built without asking triangle_ok; a parent's search (or the whole
// loop's) finds its best state among those not refused yet, asks about that one only, and
// searches again if it is refused. A refused state that no search would take cannot change any
// choice, so the result is the one asking every state would give, after far fewer questions (on a
// corner of alpe, 235k instead of 326k calls to the grower's crossing test).
template <class ChordOk, class TriangleOk>
std::optional<double> triangulate_loop(std::span<const Vec3f> points, std::span<const Index> loop,
                                       std::span<const Vec3> around, ChordOk&& chord_ok,
                                       TriangleOk&& triangle_ok, HoleScratch& scratch,
                                       std::vector<Triangle>& out) {
  const std::size_t n = loop.size();
  constexpr double kNone = -2;  // below every cosine
  if (n < 3 || around.size() != n) return std::nullopt;
  using State = HoleScratch::State;
  scratch.first.resize(n * n);
  std::size_t triangles = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 2; j < n; ++j) {
      scratch.first[i * n + j] = static_cast<std::uint32_t>(triangles);
      triangles += j - i - 1;
    }
  }
  const auto at = [&](std::size_t i, std::size_t k, std::size_t j) {
    return scratch.first[i * n + j] + (k - i - 1);
  };
  // Only the states listed in by_fold are read, so neither array needs clearing.
  if (scratch.states.size() < triangles) scratch.states.resize(triangles);
  if (scratch.by_fold.size() < triangles) scratch.by_fold.resize(triangles);
  scratch.count.assign(n * n, 0);
  scratch.verdict.assign(triangles, 0);
  // Whether triangle (i, k, j), i < k < j, may be made: its chords, its area, then triangle_ok
  // (asked once; the verdict is kept).
  const auto is_edge = [&](std::size_t a, std::size_t b) {
    return b == a + 1 || (a == 0 && b == n - 1);
  };
  const auto allowed = [&](std::size_t i, std::size_t k, std::size_t j) {
    std::uint8_t& verdict = scratch.verdict[at(i, k, j)];
    if (verdict == HoleScratch::kUnasked) {
      const Vec3 p = Vec3(points[loop[i]]);
      const bool ok = (is_edge(i, k) || chord_ok(i, k)) && (is_edge(k, j) || chord_ok(k, j)) &&
                      (is_edge(i, j) || chord_ok(i, j)) &&
                      norm2(cross(Vec3(points[loop[k]]) - p, Vec3(points[loop[j]]) - p)) > 0 &&
                      triangle_ok(i, k, j);
      verdict = ok ? HoleScratch::kAllowed : HoleScratch::kRefused;
    }
    return verdict == HoleScratch::kAllowed;
  };
  // Each loop edge a-b needs a triangle: the ears on it first (most often allowed), then the
  // rest.
  for (std::size_t a = 0; a < n; ++a) {
    const std::size_t b = (a + 1) % n;
    bool found = false;
    for (std::size_t step = 1; step + 1 < n && !found; ++step) {
      // Apexes by distance along the loop: after b, then before a, alternately.
      const std::size_t c = step % 2 == 1 ? (b + (step + 1) / 2) % n : (a + n - step / 2) % n;
      const std::size_t lo = std::min({a, b, c}), hi = std::max({a, b, c});
      found = allowed(lo, a + b + c - lo - hi, hi);
    }
    if (!found) return std::nullopt;
  }
  const auto state = [&](std::size_t i, std::size_t j, std::size_t k) -> State& {
    return scratch.states[at(i, k, j)];
  };
  const auto better = [](double fold_cos, double area, double best_cos, double best_area) {
    return fold_cos > best_cos || (fold_cos == best_cos && area < best_area);
  };
  // The best side of triangle (i, k, j) with normal `normal` on chord a-b (a loop edge when
  // b == a + 1): its fold with that triangle included.
  struct Side {
    double fold_cos, area;
    std::uint16_t apex;
  };
  const auto side = [&](std::size_t a, std::size_t b, const Vec3& normal) {
    if (b == a + 1) return Side{dot(normal, around[a]), 0, 0};
    const std::uint16_t* apexes = &scratch.by_fold[scratch.first[a * n + b]];
    // The best apex among those not refused, and only then whether its triangle may be made:
    // a refused winner is passed over and the search runs again.
    for (;;) {
      Side best{kNone, 0, 0};
      for (std::size_t r = 0; r < scratch.count[a * n + b]; ++r) {
        const std::size_t c = apexes[r];
        const State& s = state(a, b, c);
        if (s.fold_cos < best.fold_cos) break;  // nor can any after it
        if (scratch.verdict[at(a, c, b)] == HoleScratch::kRefused) continue;
        const double fold_cos = std::min(s.fold_cos, dot(normal, s.normal));
        if (better(fold_cos, s.area, best.fold_cos, best.area)) {
          best = Side{fold_cos, s.area, static_cast<std::uint16_t>(c)};
        }
      }
      if (best.fold_cos == kNone || allowed(a, best.apex, b)) return best;
    }
  };
  for (std::size_t width = 2; width < n; ++width) {
    for (std::size_t i = 0; i + width < n; ++i) {
      const std::size_t j = i + width;
      // The chord i-j is a loop edge only for (0, n-1).
      if (!(i == 0 && j == n - 1) && !chord_ok(i, j)) continue;
      for (std::size_t k = i + 1; k < j; ++k) {
        const Vec3 p = Vec3(points[loop[i]]);
        const Vec3 w = cross(Vec3(points[loop[k]]) - p, Vec3(points[loop[j]]) - p);
        const double twice_area = norm(w);
        if (!(twice_area > 0)) continue;
        const Vec3 normal = w * (1 / twice_area);
        const Side left = side(i, k, normal), right = side(k, j, normal);
        if (left.fold_cos == kNone || right.fold_cos == kNone) continue;
        state(i, j, k) =
            State{std::min(left.fold_cos, right.fold_cos),
                  left.area + right.area + 0.5 * twice_area, normal, left.apex, right.apex};
        scratch.by_fold[scratch.first[i * n + j] + scratch.count[i * n + j]++] =
            static_cast<std::uint16_t>(k);
      }
      std::uint16_t* apexes = &scratch.by_fold[scratch.first[i * n + j]];
      std::sort(apexes, apexes + scratch.count[i * n + j], [&](std::uint16_t x, std::uint16_t y) {
        const double fx = state(i, j, x).fold_cos, fy = state(i, j, y).fold_cos;
        return fx > fy || (fx == fy && x < y);
      });
    }
  }
  // The whole loop: chord 0-(n-1) is the closing loop edge.
  const Side whole = side(0, n - 1, around[n - 1]);
  if (whole.fold_cos == kNone) return std::nullopt;
  // Unwind the apexes: (i, k, j) is counter-clockwise along the loop's order.
  std::vector<std::size_t>& stack = scratch.stack;
  stack.assign({0, n - 1, whole.apex});
  while (!stack.empty()) {
    const std::size_t k = stack.back();
    stack.pop_back();
    const std::size_t j = stack.back();
    stack.pop_back();
    const std::size_t i = stack.back();
    stack.pop_back();
    out.push_back({loop[i], loop[k], loop[j]});
    const State& s = state(i, j, k);
    if (k > i + 1) stack.insert(stack.end(), {i, k, s.left});
    if (j > k + 1) stack.insert(stack.end(), {k, j, s.right});
  }
  return whole.fold_cos;
}

}  // namespace g2s::detail
