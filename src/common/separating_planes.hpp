// Separating planes: a cheap, exact-in-effect filter ahead of the exact crossing test of
// triangle_intersection.hpp. A triangle's own plane and, through each of its edges, the plane
// square to it that faces away from it: a convex set with every corner strictly beyond one of
// these planes, but for corners the triangle shares on it, meets the triangle only in those
// shared corners (its points on the plane are the hull of its corners there). So two triangles,
// one of whose corners lie so, never cross, and the exact test is not needed. This settles most
// pairs of neighbours side by side in one surface, which bounding boxes and circumballs do not:
// on a crop of a photogrammetric scan, 22.8M of the 24.8M pairs the mesher's hole filling sent
// to the exact test.
//
// "Strictly" is judged on the value computed in double with a margin: a point's side,
// n . (p - corner), is a polynomial of degree 4 in coordinate differences, evaluated 7 roundings
// deep from differences of float corners (exact in double), so its error is below 16 units of
// roundoff times the same polynomial over absolute values; the margin is 1e-13 of that (about
// 900 units), so a point on or across a plane is never taken as beyond it. Corners are shared by
// index: equal indices are one point (distinct indices at one position only make the filter
// decide less).
#pragma once

#include <array>
#include <span>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s {

class SeparatingPlanes {
 public:
  // Inputs: points (the triangles' corners index them), triangle t.
  SeparatingPlanes(std::span<const Vec3f> points, const Triangle& t);

  // Output: true when the corners of `other` that t lacks all lie strictly beyond one of t's
  // planes (on one side of t's own plane, or beyond an edge's plane with only that edge's
  // corners shared): then the two triangles do not cross (triangles_cross is false). False
  // decides nothing; in particular it is false for t itself, in any corner order.
  bool separate(std::span<const Vec3f> points, const Triangle& other) const;

 private:
  // A plane through a corner of t: a point p is strictly beyond it when normal . (p - corner)
  // exceeds kMargin times bound . |p - corner|.
  struct Plane {
    Vec3 normal, bound;
  };
  static constexpr double kMargin = 1e-13;

  Triangle t_;
  Vec3 corner0_, corner1_;
  Plane face_;                  // through corner 0
  std::array<Plane, 3> edges_;  // edge k runs from corner k to corner k + 1; 0 and 2 through
                                // corner 0, 1 through corner 1
};

}  // namespace g2s
