// why_no_surface: the degenerate clouds no mesher can turn into a surface (issue 5, bad input
// matrix): empty, one repeated point, two points, points on a line (within float precision, and
// also with one stray point off it). Coplanar clouds are not degenerate: a flat scan is a valid
// open surface. The points are visited in passes, so a tile store is checked in bounded memory.
#include "g2s/surface_check.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <utility>
#include <vector>

namespace g2s {
namespace {

using Point = std::array<double, 3>;

// Points on a line besides one stray point for the cloud to count as a line.
constexpr std::uint64_t kFewestOnLineWithStray = 10;

// Widest extent along an axis that float (up to 3.4e38) holds with room to spare.
constexpr double kWidestSpan = 1e38;
// Narrowest extent of a cloud (along its widest axis) that float holds with room to spare: below
// float's normal numbers (1.2e-38) coordinates keep fewer than 24 bits, down to one bit at 1e-45,
// so the mesher's float frame would round neighbours together. At 1e-30 a float step (at most
// 1.4e-45 there) is still below a millionth of the spacing of a cloud of up to 1e18 points.
constexpr double kNarrowestSpan = 1e-30;

double distance2(const Point& a, const Point& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

Point to_point(const double* p) {
  return {p[0], p[1], p[2]};
}

// Calls f(point) for every point `each` visits, a run at a time (f inlined in the loop).
template <typename F>
void for_each_point(const PointVisitor& each, F&& f) {
  each([&f](std::span<const double> xyz) {
    for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) f(to_point(&xyz[i]));
  });
}

// The point farthest from `from` (the first of equals), leaving out `skip` when given.
Point farthest_from(const PointVisitor& each, const Point& from, const Point* skip = nullptr) {
  Point best = from;
  double best_d2 = -1.0;
  for_each_point(each, [&](const Point& p) {
    if (skip != nullptr && p == *skip) return;
    const double d2 = distance2(p, from);
    if (d2 > best_d2) best = p, best_d2 = d2;
  });
  return best;
}

// The squared distance of p from the line through a with unit direction `axis`.
double off_line2(const Point& p, const Point& a, const Point& axis) {
  const Point d{p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const Point off{d[1] * axis[2] - d[2] * axis[1], d[2] * axis[0] - d[0] * axis[2],
                  d[0] * axis[1] - d[1] * axis[0]};
  return off[0] * off[0] + off[1] * off[1] + off[2] * off[2];
}

Point unit(const Point& a, const Point& b) {
  const double length = std::sqrt(distance2(a, b));
  return {(b[0] - a[0]) / length, (b[1] - a[1]) / length, (b[2] - a[2]) / length};
}

// How many points (but those equal to `skip`) lie farther than `tolerance` from the line
// through a and b (a != b), counted up to 2, and the first two of them; the rest of the pass
// costs a comparison per point once two are found.
std::size_t count_off_line(const PointVisitor& each, const Point& a, const Point& b,
                           double tolerance, std::array<Point, 2>& off,
                           const Point* skip = nullptr) {
  const Point axis = unit(a, b);
  std::size_t off_line = 0;
  for_each_point(each, [&](const Point& p) {
    if (off_line >= 2 || (skip != nullptr && p == *skip)) return;
    if (off_line2(p, a, axis) > tolerance * tolerance) off[off_line++] = p;
  });
  return off_line;
}

// Whether the three points may lie within `tolerance` of one line: twice their triangle's area
// is at most about tolerance times its longest side then (generously: four times).
bool maybe_collinear(const Point& p, const Point& q, const Point& r, double tolerance) {
  const Point u{q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  const Point v{r[0] - p[0], r[1] - p[1], r[2] - p[2]};
  const Point cross{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0]};
  const double longest = std::sqrt(std::max({distance2(p, q), distance2(p, r), distance2(q, r)}));
  return std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]) <=
         4.0 * tolerance * longest;
}

// Whether four of `points` have no three within `tolerance` of one line: no three may lie on
// one (maybe_collinear says no for each of the four triples). Three points within t of a line
// have a height of at most 2t over their longest side, so twice their area is at most 2t times
// that side, half of what maybe_collinear allows; every line then misses two of the four.
bool four_off_every_line(std::span<const Point> points, double tolerance) {
  const std::size_t n = points.size();
  const auto apart = [&](std::size_t i, std::size_t j, std::size_t k) {
    return !maybe_collinear(points[i], points[j], points[k], tolerance);
  };
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        if (!apart(i, j, k)) continue;
        for (std::size_t l = k + 1; l < n; ++l) {
          if (apart(i, j, l) && apart(i, k, l) && apart(j, k, l)) return true;
        }
      }
    }
  }
  return false;
}

std::size_t count_distinct(const PointVisitor& each, std::uint64_t n) {
  std::vector<Point> points;
  points.reserve(n);
  for_each_point(each, [&](const Point& p) { points.push_back(p); });
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
  const double widest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (widest > 0 && widest < kNarrowestSpan) {
    return fmt::format(
        "the points span at most {:.3g} along any axis, too small for the float coordinates the "
        "mesher works in (below {:.0e} they lose precision; scale the coordinates up)",
        widest, kNarrowestSpan);
  }
  return "";
}

std::string why_no_surface(const PointCloud& cloud) {
  return why_no_surface(cloud.size(), [&cloud](const PointRun& visit) { visit(cloud.xyz); });
}

std::string why_no_surface(std::uint64_t n, const PointVisitor& each) {
  if (n == 0) return "the cloud has no points";
  double lo[3], hi[3];
  for (int axis = 0; axis < 3; ++axis) {
    lo[axis] = std::numeric_limits<double>::infinity();
    hi[axis] = -std::numeric_limits<double>::infinity();
  }
  // The bounds, and the point farthest from the first one, in one pass. Two sweeps of "farthest
  // point" give two points nearly a diameter apart: the line through them is the candidate for
  // a line holding every point.
  // The pass also keeps the first point reaching each bound: with the first point and the
  // farthest, eight points that settle a real cloud at once (below).
  Point first{};
  bool have_first = false;
  Point a{};
  double a_d2 = -1.0;
  std::array<Point, 8> extremes{};  // lowest x, y, z, highest x, y, z, first, farthest
  for_each_point(each, [&](const Point& p) {
    if (!have_first) first = p, have_first = true;
    for (int axis = 0; axis < 3; ++axis) {
      if (p[axis] < lo[axis]) lo[axis] = p[axis], extremes[axis] = p;
      if (p[axis] > hi[axis]) hi[axis] = p[axis], extremes[3 + axis] = p;
    }
    const double d2 = distance2(p, first);
    if (d2 > a_d2) a = p, a_d2 = d2;
  });
  if (std::string why = why_beyond_float(lo, hi); !why.empty()) return why;
  // Every line test below has a tolerance of a millionth of the length between two points, no
  // more than a millionth of the box's diagonal. Four points of which no line within that holds
  // three leave two points off every such line, stray or not: the answer is "" without the
  // further passes.
  extremes[6] = first;
  extremes[7] = a;
  const double diagonal = std::sqrt(distance2({lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}));
  if (four_off_every_line(extremes, 1e-6 * diagonal)) return "";
  const Point b = farthest_from(each, a);
  const double length2 = distance2(a, b);
  if (length2 == 0.0) {
    return n == 1 ? "the cloud has a single point"
                  : fmt::format("all {} points are the same point", n);
  }
  // Float keeps about 7 digits: points closer to the line than a millionth of the extent are on
  // it for the mesher (which works in float around each tile's centre).
  const double tolerance = 1e-6 * std::sqrt(length2);
  std::string stray;
  std::array<Point, 2> off{};
  const std::size_t off_line = count_off_line(each, a, b, tolerance, off);
  // One point off a line of many is a stray point: a fan of slivers is no surface. A few points
  // (a triangle, a line of three and a point) are left to the mesher.
  const bool stray_allowed = n > kFewestOnLineWithStray;
  bool on_one_line = off_line == 0 || (off_line == 1 && stray_allowed);
  if (off_line == 1) {
    stray = fmt::format(" but the one at ({}, {}, {})", off[0][0], off[0][1], off[0][2]);
  }
  // A stray point may also be a or b itself: the line then holds the other one and both points
  // found off the line through a and b (a quick test that settles real clouds), and is the line
  // through the other and the point farthest from it, the stray point left out.
  for (const auto& [end, out] : {std::pair{a, b}, std::pair{b, a}}) {
    if (on_one_line || !stray_allowed || !maybe_collinear(end, off[0], off[1], tolerance)) {
      continue;
    }
    const Point other = farthest_from(each, end, &out);
    if (other == end) continue;
    const double tolerance_without = 1e-6 * std::sqrt(distance2(end, other));
    std::array<Point, 2> off_without{};
    if (count_off_line(each, end, other, tolerance_without, off_without, &out) == 0) {
      on_one_line = true;
      stray = fmt::format(" but the one at ({}, {}, {})", out[0], out[1], out[2]);
    }
  }
  if (!on_one_line) return "";
  const std::size_t distinct = count_distinct(each, n);
  if (distinct == 2) {
    return fmt::format("the cloud has only 2 distinct points ({} in all)", n);
  }
  return fmt::format(
      "all {} points ({} distinct){} lie on one straight line (to within {:.3g}, a "
      "millionth of their extent)",
      n, distinct, stray, tolerance);
}

}  // namespace g2s
