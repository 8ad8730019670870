// Separating planes (separating_planes.hpp) over float points: the mesher's case, compiled once
// here rather than inlined into each caller (on a corner of alpe, 1% fewer instructions).
#include "common/separating_planes.hpp"

namespace g2s {

SeparatingPlanes::SeparatingPlanes(std::span<const Vec3f> points, const Triangle& t)
    : SeparatingPlanes(t, [&](Index v) { return Vec3(points[v]); }) {
  checks_range_ = false;  // differences of floats lie between 1.4e-45 and 6.9e38
}

bool SeparatingPlanes::separate(std::span<const Vec3f> points, const Triangle& other) const {
  return separate(other, [&](Index v) { return Vec3(points[v]); });
}

}  // namespace g2s
