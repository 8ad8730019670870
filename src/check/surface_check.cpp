// why_no_surface: the degenerate clouds no mesher can turn into a surface (issue 5, bad input
// matrix): empty, one repeated point, two points, points on a line. Coplanar clouds are not
// degenerate: a flat scan is a valid open surface.
#include "g2s/surface_check.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace g2s {
namespace {

using Point = std::array<double, 3>;

// Widest extent along an axis that float (up to 3.4e38) holds with room to spare.
constexpr double kWidestSpan = 1e38;

Point point_at(const PointCloud& cloud, std::size_t i) {
  return {cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]};
}

double distance2(const Point& a, const Point& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

// The point farthest from `from` (the first of equals).
std::size_t farthest_from(const PointCloud& cloud, const Point& from) {
  std::size_t best = 0;
  double best_d2 = -1.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double d2 = distance2(point_at(cloud, i), from);
    if (d2 > best_d2) best = i, best_d2 = d2;
  }
  return best;
}

std::size_t count_distinct(const PointCloud& cloud) {
  std::vector<Point> points(cloud.size());
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = point_at(cloud, i);
  std::sort(points.begin(), points.end());
  return static_cast<std::size_t>(std::unique(points.begin(), points.end()) - points.begin());
}

}  // namespace

std::string why_beyond_float(const double lo[3], const double hi[3]) {
  // The mesher works in float around a tile's centre: a wider cloud (a wild coordinate such as
  // 1e300) would turn into infinities there, and squared distances overflow in double.
  for (int axis = 0; axis < 3; ++axis) {
    if (!(hi[axis] - lo[axis] <= kWidestSpan)) {
      return fmt::format(
          "the points span {:.3g} along {}, beyond the range of the float coordinates the mesher "
          "works in (a wild coordinate?)",
          hi[axis] - lo[axis], "xyz"[axis]);
    }
  }
  return "";
}

std::string why_no_surface(const PointCloud& cloud) {
  const std::size_t n = cloud.size();
  if (n == 0) return "the cloud has no points";
  double lo[3], hi[3];
  for (int axis = 0; axis < 3; ++axis) {
    lo[axis] = hi[axis] = cloud.xyz[axis];
    for (std::size_t i = 0; i < n; ++i) {
      lo[axis] = std::min(lo[axis], cloud.xyz[3 * i + axis]);
      hi[axis] = std::max(hi[axis], cloud.xyz[3 * i + axis]);
    }
  }
  if (std::string why = why_beyond_float(lo, hi); !why.empty()) return why;
  // Two sweeps of "farthest point" give two points nearly a diameter apart: the line through
  // them is the only candidate for a line holding every point.
  const Point a = point_at(cloud, farthest_from(cloud, point_at(cloud, 0)));
  const Point b = point_at(cloud, farthest_from(cloud, a));
  const double length2 = distance2(a, b);
  if (length2 == 0.0) {
    return n == 1 ? "the cloud has a single point"
                  : fmt::format("all {} points are the same point", n);
  }
  const double length = std::sqrt(length2);
  const Point axis{(b[0] - a[0]) / length, (b[1] - a[1]) / length, (b[2] - a[2]) / length};
  // Float keeps about 7 digits: points closer to the line than this are on it for the mesher.
  const double tolerance = 1e-6 * length;
  for (std::size_t i = 0; i < n; ++i) {
    const Point p = point_at(cloud, i);
    const Point d{p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    const Point off{d[1] * axis[2] - d[2] * axis[1], d[2] * axis[0] - d[0] * axis[2],
                    d[0] * axis[1] - d[1] * axis[0]};
    if (off[0] * off[0] + off[1] * off[1] + off[2] * off[2] > tolerance * tolerance) return "";
  }
  const std::size_t distinct = count_distinct(cloud);
  if (distinct == 2) {
    return fmt::format("the cloud has only 2 distinct points ({} in all)", n);
  }
  return fmt::format(
      "all {} points ({} distinct) lie on one straight line (to within {:.3g}, a millionth of "
      "their extent)",
      n, distinct, tolerance);
}

}  // namespace g2s
