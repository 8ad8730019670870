// Hole triangulation helpers (hole_filling.hpp).
#include "grow/hole_filling.hpp"

namespace g2s::detail {

double triangle_area(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  return 0.5 * norm(cross(Vec3(b) - Vec3(a), Vec3(c) - Vec3(a)));
}

}  // namespace g2s::detail
