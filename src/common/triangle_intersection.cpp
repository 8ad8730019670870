// Exact triangle-pair crossing test (triangle_intersection.hpp). Two closed triangles meet if
// and only if an edge of one meets the other (if they meet and no edge of either meets the other,
// one would have to lie inside the other without its edges, which a closed triangle cannot), so
// the test is built from one primitive, closed segment against closed triangle:
// - the segment's ends on one strict side of the triangle's plane: apart;
// - the segment in the plane: a 2D test in the coordinate plane where the triangle projects
//   without degenerating (an end inside, or the segment meeting an edge);
// - otherwise the segment meets the plane in one point, which lies in the closed triangle when the
//   three orientations of the segment's line against the triangle's edges do not differ in sign.
// Shared corners change the question only: with one shared corner v, the two convex sets meet
// beyond v exactly when the edge opposite v in one meets the other triangle (the meeting set runs
// from v to where it first leaves one triangle, which is through the edge opposite v); with a
// shared edge, two triangles in different planes meet only in the edge, coplanar ones overlap
// when their third corners lie on the same side of it.
#include "common/triangle_intersection.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "common/exact_predicates.hpp"

namespace g2s {
namespace {

using Point = const double*;
using exact::orient2d;
using exact::orient3d;

bool same_point(Point p, Point q) {
  return p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
}

// The coordinate plane (i, j) in which triangle p projects without degenerating: the one
// dropping the axis of the normal's largest component, or another if rounding made that one
// exactly zero. Sets the triangle's orientation there.
void projection_plane(Point p0, Point p1, Point p2, int& i, int& j, int& orientation) {
  const double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
  const double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
  const double n[3] = {std::fabs(u[1] * v[2] - u[2] * v[1]), std::fabs(u[2] * v[0] - u[0] * v[2]),
                       std::fabs(u[0] * v[1] - u[1] * v[0])};
  int dropped = n[0] >= n[1] ? (n[0] >= n[2] ? 0 : 2) : (n[1] >= n[2] ? 1 : 2);
  for (int attempt = 0; attempt < 3; ++attempt, dropped = (dropped + 1) % 3) {
    i = (dropped + 1) % 3;
    j = (dropped + 2) % 3;
    orientation = orient2d(p0, p1, p2, i, j);
    if (orientation != 0) return;
  }
}

// Closed segments [a, b] and [c, d], collinear with each other, overlap: their boxes overlap.
bool collinear_overlap(Point a, Point b, Point c, Point d, int i, int j) {
  for (const int k : {i, j}) {
    if (std::max(a[k], b[k]) < std::min(c[k], d[k])) return false;
    if (std::max(c[k], d[k]) < std::min(a[k], b[k])) return false;
  }
  return true;
}

// Closed segments [a, b] and [c, d] (each of two distinct points) meet, in the plane (i, j).
bool segments_meet_2d(Point a, Point b, Point c, Point d, int i, int j) {
  const int c_side = orient2d(a, b, c, i, j), d_side = orient2d(a, b, d, i, j);
  if (c_side * d_side > 0) return false;
  if (c_side == 0 && d_side == 0) return collinear_overlap(a, b, c, d, i, j);
  const int a_side = orient2d(c, d, a, i, j), b_side = orient2d(c, d, b, i, j);
  return a_side * b_side <= 0;
}

// Closed segment [s, t] meets closed triangle p, all in one plane.
bool coplanar_segment_meets_triangle(Point s, Point t, const Point p[3]) {
  int i, j, orientation;
  projection_plane(p[0], p[1], p[2], i, j, orientation);
  auto inside = [&](Point x) {
    for (int e = 0; e < 3; ++e) {
      if (orient2d(p[e], p[(e + 1) % 3], x, i, j) * orientation < 0) return false;
    }
    return true;
  };
  if (inside(s) || inside(t)) return true;
  for (int e = 0; e < 3; ++e) {
    if (segments_meet_2d(s, t, p[e], p[(e + 1) % 3], i, j)) return true;
  }
  return false;
}

// Closed segment [s, t] meets closed triangle p; s_side, t_side are orient3d(p0, p1, p2, s / t).
bool segment_meets_triangle(Point s, Point t, int s_side, int t_side, const Point p[3]) {
  if (s_side * t_side > 0) return false;
  if (s_side == 0 && t_side == 0) return coplanar_segment_meets_triangle(s, t, p);
  const int e0 = orient3d(s, t, p[0], p[1]);
  const int e1 = orient3d(s, t, p[1], p[2]);
  if (e0 * e1 < 0) return false;
  const int e2 = orient3d(s, t, p[2], p[0]);
  return e0 * e2 >= 0 && e1 * e2 >= 0;
}

bool boxes_apart(const Point a[3], const Point b[3]) {
  for (int k = 0; k < 3; ++k) {
    const double a_min = std::min({a[0][k], a[1][k], a[2][k]});
    const double a_max = std::max({a[0][k], a[1][k], a[2][k]});
    const double b_min = std::min({b[0][k], b[1][k], b[2][k]});
    const double b_max = std::max({b[0][k], b[1][k], b[2][k]});
    if (a_max < b_min || b_max < a_min) return true;
  }
  return false;
}

bool strictly_one_side(const int side[3]) {
  return (side[0] > 0 && side[1] > 0 && side[2] > 0) || (side[0] < 0 && side[1] < 0 && side[2] < 0);
}

// The corner of a triangle alone on its side of a plane, given the three corners' sides (none
// zero, not all equal).
int alone(const int side[3]) {
  return side[0] == side[1] ? 2 : side[0] == side[2] ? 1 : 0;
}

// No shared corner, each triangle with one corner strictly on one side of the other's plane and
// two strictly on the other (Guigue and Devillers' test): each meets the other's plane in a
// segment on the planes' common line, and the triangles meet when those segments overlap. With
// a's lone corner p1 above b's plane (b's order reversed if need be) and b's lone corner p2
// above a's plane (a's other corners swapped if need be), a's segment starts on edge p1 r1 and
// ends on p1 q1, b's starts on p2 q2 and ends on p2 r2, along the line; they overlap when b's
// start is not after a's end and a's start not after b's end, two orientations.
bool straddling_triangles_meet(const Point a[3], const int a_side[3], const Point b[3],
                               const int b_side[3]) {
  const int i = alone(a_side);
  Point p1 = a[i], q1 = a[(i + 1) % 3], r1 = a[(i + 2) % 3];
  // b as it faces with p1 above its plane, with its sides against a's plane.
  const bool reverse_b = a_side[i] < 0;
  const Point b_order[3] = {b[0], reverse_b ? b[2] : b[1], reverse_b ? b[1] : b[2]};
  const int b_order_side[3] = {b_side[0], reverse_b ? b_side[2] : b_side[1],
                               reverse_b ? b_side[1] : b_side[2]};
  const int j = alone(b_order_side);
  const Point p2 = b_order[j], q2 = b_order[(j + 1) % 3], r2 = b_order[(j + 2) % 3];
  if (b_order_side[j] < 0) std::swap(q1, r1);
  return orient3d(p1, q1, p2, q2) <= 0 && orient3d(p1, r1, p2, r2) >= 0;
}

// No shared corner: any common point.
bool triangles_meet(const Point a[3], const Point b[3]) {
  int b_side[3];  // b's corners against a's plane
  for (int k = 0; k < 3; ++k) b_side[k] = orient3d(a[0], a[1], a[2], b[k]);
  if (strictly_one_side(b_side)) return false;
  int a_side[3];
  for (int k = 0; k < 3; ++k) a_side[k] = orient3d(b[0], b[1], b[2], a[k]);
  if (strictly_one_side(a_side)) return false;
  if (a_side[0] * a_side[1] * a_side[2] != 0 && b_side[0] * b_side[1] * b_side[2] != 0) {
    return straddling_triangles_meet(a, a_side, b, b_side);
  }
  for (int e = 0; e < 3; ++e) {
    const int f = (e + 1) % 3;
    if (segment_meets_triangle(a[e], a[f], a_side[e], a_side[f], b)) return true;
    if (segment_meets_triangle(b[e], b[f], b_side[e], b_side[f], a)) return true;
  }
  return false;
}

// One shared corner, a[0] == b[0]: a common point other than it.
// A triangle whose other two corners lie strictly on one side of the other's plane meets that
// plane, and so the other triangle, only in the shared corner.
bool triangles_meet_beyond_corner(const Point a[3], const Point b[3]) {
  const int a1 = orient3d(b[0], b[1], b[2], a[1]), a2 = orient3d(b[0], b[1], b[2], a[2]);
  if (a1 * a2 > 0) return false;
  if (segment_meets_triangle(a[1], a[2], a1, a2, b)) return true;
  const int b1 = orient3d(a[0], a[1], a[2], b[1]), b2 = orient3d(a[0], a[1], a[2], b[2]);
  return segment_meets_triangle(b[1], b[2], b1, b2, a);
}

// A shared edge p q; r and s are the other corners: coplanar and on the same side of p q.
bool triangles_fold_onto_edge(Point p, Point q, Point r, Point s) {
  if (orient3d(p, q, r, s) != 0) return false;
  int i, j, r_side;
  const Point triangle[3] = {p, q, r};
  projection_plane(triangle[0], triangle[1], triangle[2], i, j, r_side);
  return orient2d(p, q, s, i, j) == r_side;
}

}  // namespace

bool triangles_cross(const double* const a[3], const double* const b[3]) {
  if (boxes_apart(a, b)) return false;
  int shared = 0, a_shared[3], b_shared[3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (same_point(a[i], b[j])) {
        a_shared[shared] = i;
        b_shared[shared] = j;
        ++shared;
      }
    }
  }
  switch (shared) {
    case 0:
      return triangles_meet(a, b);
    case 1: {
      const int i = a_shared[0], j = b_shared[0];
      const Point a_from_v[3] = {a[i], a[(i + 1) % 3], a[(i + 2) % 3]};
      const Point b_from_v[3] = {b[j], b[(j + 1) % 3], b[(j + 2) % 3]};
      return triangles_meet_beyond_corner(a_from_v, b_from_v);
    }
    case 2: {
      const int r = 3 - a_shared[0] - a_shared[1], s = 3 - b_shared[0] - b_shared[1];
      return triangles_fold_onto_edge(a[a_shared[0]], a[a_shared[1]], a[r], b[s]);
    }
    default:
      return true;
  }
}

namespace {
// The test on corners of any 3-vector type, converted to double in one step.
template <class Corner>
bool cross_in_double(const Corner a[3], const Corner b[3]) {
  double a_xyz[3][3], b_xyz[3][3];
  for (int k = 0; k < 3; ++k) {
    a_xyz[k][0] = a[k].x, a_xyz[k][1] = a[k].y, a_xyz[k][2] = a[k].z;
    b_xyz[k][0] = b[k].x, b_xyz[k][1] = b[k].y, b_xyz[k][2] = b[k].z;
  }
  const double* const a_corners[3] = {a_xyz[0], a_xyz[1], a_xyz[2]};
  const double* const b_corners[3] = {b_xyz[0], b_xyz[1], b_xyz[2]};
  return triangles_cross(a_corners, b_corners);
}
}  // namespace

bool triangles_cross(const Vec3 a[3], const Vec3 b[3]) {
  return cross_in_double(a, b);
}

bool triangles_cross(const Vec3f a[3], const Vec3f b[3]) {
  return cross_in_double(a, b);
}

}  // namespace g2s
