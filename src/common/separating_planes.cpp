// Separating planes (separating_planes.hpp): the planes and the side tests, face first (it
// settles most pairs: neighbours lie beside a triangle, above or below its plane), then edges.
#include "common/separating_planes.hpp"

#include <cmath>

namespace g2s {
namespace {

Vec3 absolute(const Vec3& v) {
  return {std::abs(v.x), std::abs(v.y), std::abs(v.z)};
}
// cross(a, b) over absolute values, for a, b of non-negative components.
Vec3 cross_bound(const Vec3& a, const Vec3& b) {
  return {a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x};
}

}  // namespace

SeparatingPlanes::SeparatingPlanes(std::span<const Vec3f> points, const Triangle& t) : t_(t) {
  const Vec3 corner[3] = {Vec3(points[t[0]]), Vec3(points[t[1]]), Vec3(points[t[2]])};
  corner0_ = corner[0];
  corner1_ = corner[1];
  const Vec3 u = corner[1] - corner[0], v = corner[2] - corner[0];
  face_ = {cross(u, v), cross_bound(absolute(u), absolute(v))};
  for (int k = 0; k < 3; ++k) {
    const Vec3 edge = corner[(k + 1) % 3] - corner[k];
    edges_[k] = {cross(edge, face_.normal), cross_bound(absolute(edge), face_.bound)};
  }
}

bool SeparatingPlanes::separate(std::span<const Vec3f> points, const Triangle& other) const {
  // The corners t lacks, from t's corner 0 (which lies on the face and on edges 0 and 2).
  Vec3 p[3], d[3], a[3];
  int own[3];  // per corner of other: its place in t, or -1 if t lacks it
  int count = 0, face_side = 0;
  bool face = true;
  for (int i = 0; i < 3; ++i) {
    const Index v = other[i];
    own[i] = v == t_[0] ? 0 : v == t_[1] ? 1 : v == t_[2] ? 2 : -1;
    if (own[i] >= 0) continue;
    p[i] = Vec3(points[v]);
    d[i] = p[i] - corner0_;
    a[i] = absolute(d[i]);
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
      }
      beyond = dot(edges_[k].normal, from) > kMargin * dot(edges_[k].bound, bound);
    }
    if (beyond) return true;
  }
  return false;
}

}  // namespace g2s
