// Small 3-vectors for the geometry of the mesher: float for storage (points are many), double
// for predicates (circumcentres of thin triangles need the precision).
#pragma once

#include <algorithm>
#include <cmath>

namespace g2s {

struct Vec3f {
  float x, y, z;
};

struct Vec3 {
  double x, y, z;
  Vec3() = default;
  constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
  explicit Vec3(const Vec3f& v) : x(v.x), y(v.y), z(v.z) {}
  Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
};

inline double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm2(const Vec3& a) {
  return dot(a, a);
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
inline Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return n > 0 ? a * (1.0 / n) : Vec3{0, 0, 0};
}

// The smallest ball through a, b, c: centre at the circumcentre (in the triangle's plane),
// radius^2 = the squared circumradius. False when the triangle is (nearly) degenerate.
struct Ball {
  Vec3 centre;
  double radius2;
};

// Whether a triangle with edge vectors u = b - a, v = c - a (w = u x v) and third side c - b is
// no sliver. The smallest angle lies between the two longest edges, and its squared sine is
// |w|^2 over the product of their squared lengths. Below ~0.006 degrees the circumcentre is
// numerically meaningless and, written out, the triangle may become exactly collinear.
inline bool not_a_sliver(double w2, double uu, double vv, double cc) {
  const double longest = std::max({uu, vv, cc});
  const double second = uu + vv + cc - longest - std::min({uu, vv, cc});
  return w2 > 1e-8 * longest * second;
}

// Whether a, b, c have a circumball (circumball would succeed).
inline bool has_circumball(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u = b - a, v = c - a;
  return not_a_sliver(norm2(cross(u, v)), norm2(u), norm2(v), norm2(c - b));
}

inline bool circumball(const Vec3& a, const Vec3& b, const Vec3& c, Ball& out) {
  const Vec3 u = b - a;
  const Vec3 v = c - a;
  const Vec3 w = cross(u, v);
  const double w2 = norm2(w);
  const double uu = norm2(u);
  const double vv = norm2(v);
  if (!not_a_sliver(w2, uu, vv, norm2(c - b))) return false;
  const Vec3 offset = (cross(w, u) * vv + cross(v, w) * uu) * (0.5 / w2);
  out.centre = a + offset;
  out.radius2 = norm2(offset);
  return true;
}

// The point of triangle a b c closest to p (Ericson, Real-Time Collision Detection, 5.1.5):
// the vertex, edge or face region p projects into, from the signs of a few dot products.
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double scale = 1.0 / (va + vb + vc);
  return a + ab * (vb * scale) + ac * (vc * scale);
}

}  // namespace g2s
