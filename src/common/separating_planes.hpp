// Separating planes: a cheap, exact-in-effect filter ahead of the exact crossing test of
// triangle_intersection.hpp. A triangle's own plane and, through each of its edges, the plane
// square to it that faces away from it: a convex set with every corner strictly beyond one of
// these planes, but for corners the triangle shares on it, meets the triangle only in those
// shared corners (its points on the plane are the hull of its corners there). So two triangles,
// one of whose corners lie so, never cross, and the exact test is not needed. This settles most
// pairs of neighbours side by side in one surface, which bounding boxes and circumballs do not:
// on a crop of a photogrammetric scan, 22.8M of the 24.8M pairs that the mesher's hole filling
// sent to the exact test before (after a test of circumballs).
//
// "Strictly" is judged on the value computed in double with a margin: a point's side,
// n . (p - corner), is a polynomial of degree 4 in coordinate differences, evaluated 7 roundings
// deep from differences that carry one rounding each (none for float corners), so its error is
// below 16 units of roundoff times the same polynomial over absolute values; the margin is 1e-13
// of that (about 900 units), so a point on or across a plane is never taken as beyond it. The
// bound holds while no product under- or overflows: every nonzero coordinate difference must lie
// between 1e-60 and 1e60 in magnitude (then no product of up to four, nor of their differences,
// leaves the normal range). Differences of floats always do; for double positions the planes
// decide nothing where one does not. Corners are shared by index: equal indices are one point
// (distinct indices at one position only make the filter decide less).
#pragma once

#include <array>
#include <cmath>
#include <span>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s {

class SeparatingPlanes {
 public:
  // Inputs: triangle t, and position(v), the position (a Vec3) of point v, for t's corners.
  template <class Position>
  SeparatingPlanes(const Triangle& t, Position&& position);
  // The same over float points, which t's corners index.
  SeparatingPlanes(std::span<const Vec3f> points, const Triangle& t);

  // Inputs: another triangle, and position as above (asked only for corners t lacks).
  // Output: true when the corners of `other` that t lacks all lie strictly beyond one of t's
  // planes (on one side of t's own plane, or beyond an edge's plane with only that edge's
  // corners shared): then the two triangles do not cross (triangles_cross is false). False
  // decides nothing; in particular it is false for t itself, in any corner order.
  template <class Position>
  bool separate(const Triangle& other, Position&& position) const;
  bool separate(std::span<const Vec3f> points, const Triangle& other) const;

 private:
  // A plane through a corner of t: a point p is strictly beyond it when normal . (p - corner)
  // exceeds kMargin times bound . |p - corner|.
  struct Plane {
    Vec3 normal, bound;
  };
  static constexpr double kMargin = 1e-13;
  static Vec3 absolute(const Vec3& v) { return {std::abs(v.x), std::abs(v.y), std::abs(v.z)}; }
  // Whether an absolute difference's nonzero components lie in [1e-60, 1e60] (see the top).
  static bool in_range(const Vec3& a) {
    const auto ok = [](double c) { return c == 0 || (c >= 1e-60 && c <= 1e60); };
    return ok(a.x) && ok(a.y) && ok(a.z);
  }
  // cross(a, b) over absolute values, for a, b of non-negative components.
  static Vec3 cross_bound(const Vec3& a, const Vec3& b) {
    return {a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x};
  }

  Triangle t_;
  bool checks_range_ = true;  // false for float corners, whose differences are always in range
  bool usable_ = true;        // t's own edges are in range
  Vec3 corner0_, corner1_;
  Plane face_;                  // through corner 0
  std::array<Plane, 3> edges_;  // edge k runs from corner k to corner k + 1; 0 and 2 through
                                // corner 0, 1 through corner 1
};

template <class Position>
SeparatingPlanes::SeparatingPlanes(const Triangle& t, Position&& position) : t_(t) {
  const Vec3 corner[3] = {position(t[0]), position(t[1]), position(t[2])};
  corner0_ = corner[0];
  corner1_ = corner[1];
  const Vec3 u = corner[1] - corner[0], v = corner[2] - corner[0];
  usable_ =
      in_range(absolute(u)) && in_range(absolute(v)) && in_range(absolute(corner[2] - corner[1]));
  face_ = {cross(u, v), cross_bound(absolute(u), absolute(v))};
  for (int k = 0; k < 3; ++k) {
    const Vec3 edge = corner[(k + 1) % 3] - corner[k];
    edges_[k] = {cross(edge, face_.normal), cross_bound(absolute(edge), face_.bound)};
  }
}

// The face first (it settles most pairs: neighbours lie beside a triangle, above or below its
// plane), then the edges.
template <class Position>
bool SeparatingPlanes::separate(const Triangle& other, Position&& position) const {
  if (!usable_) return false;
  // The corners t lacks, from t's corner 0 (which lies on the face and on edges 0 and 2).
  Vec3 p[3], d[3], a[3];
  int own[3];  // per corner of other: its place in t, or -1 if t lacks it
  int count = 0, face_side = 0;
  bool face = true;
  for (int i = 0; i < 3; ++i) {
    const Index v = other[i];
    own[i] = v == t_[0] ? 0 : v == t_[1] ? 1 : v == t_[2] ? 2 : -1;
    if (own[i] >= 0) continue;
    p[i] = position(v);
    d[i] = p[i] - corner0_;
    a[i] = absolute(d[i]);
    if (checks_range_ && !in_range(a[i])) return false;
    ++count;
    if (!face) continue;
    const double value = dot(face_.normal, d[i]), margin = kMargin * dot(face_.bound, a[i]);
    const int sign = value > margin ? 1 : value < -margin ? -1 : 0;
    face = sign != 0 && sign != -face_side;
    face_side = sign;
  }
  if (count == 0) return false;  // t itself
  if (face) return true;
  for (int k = 0; k < 3; ++k) {
    bool beyond = true;
    for (int i = 0; i < 3 && beyond; ++i) {
      if (own[i] >= 0) {
        beyond = own[i] == k || own[i] == (k + 1) % 3;  // on the edge
        continue;
      }
      // Edges 0 and 2 pass through corner 0, edge 1 through corner 1.
      Vec3 from = d[i], bound = a[i];
      if (k == 1) {
        from = p[i] - corner1_;
        bound = absolute(from);
        if (checks_range_ && !in_range(bound)) return false;
      }
      beyond = dot(edges_[k].normal, from) > kMargin * dot(edges_[k].bound, bound);
    }
    if (beyond) return true;
  }
  return false;
}

}  // namespace g2s
