// The mesher's float frame. Points are meshed in float (the hash grid and the grower store 3
// floats a point), relative to an origin near a box: the box of a tile's points (in the tile and
// in its seams), or a whole cloud's (origin() says which). The offset is taken in double before
// rounding, so georeferenced coordinates (around 1e7) keep float's precision. Every stage converts
// through here, so the same point of the same box gets the same float wherever it is meshed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "common/vec3.hpp"

namespace g2s {

class LocalFrame {
 public:
  LocalFrame(const double lo[3], const double hi[3]) {
    for (int a = 0; a < 3; ++a) centre_[a] = origin(lo[a], hi[a]);
  }
  // Appends point p (3 doubles) in the frame to `out`.
  void append(const double* p, std::vector<float>& out) const {
    for (int a = 0; a < 3; ++a) out.push_back(static_cast<float>(p[a] - centre_[a]));
  }
  // Point p (3 doubles) in the frame, as append() gives it.
  Vec3f point(const double* p) const {
    return {static_cast<float>(p[0] - centre_[0]), static_cast<float>(p[1] - centre_[1]),
            static_cast<float>(p[2] - centre_[2])};
  }
  // How far the box [lo, hi] reaches from the origin along any axis: float rounds the box's
  // points in the frame to steps proportional to it.
  double reach(const double lo[3], const double hi[3]) const {
    double r = 0;
    for (int a = 0; a < 3; ++a) {
      r = std::max({r, std::abs(lo[a] - centre_[a]), std::abs(hi[a] - centre_[a])});
    }
    return r;
  }
  // Whether point p's float in the frame (point()) is p less the origin exactly, and so whether
  // the mesher decides on p itself: always for floats read from a file (see origin()), not for
  // coordinates finer than float (a double PLY, a LAS file's scaled integers).
  bool exact(const double* p) const {
    for (int a = 0; a < 3; ++a) {
      // d = p - origin rounded, and the rounding error (TwoSum): exact when it is 0.
      const double d = p[a] - centre_[a], back = d - p[a];
      const double error = (p[a] - (d - back)) + (-centre_[a] - back);
      if (error != 0 || static_cast<double>(static_cast<float>(d)) != d) return false;
    }
    return true;
  }
  // Whether every point of xyz (3 doubles each) is exact in the frame.
  bool exact(std::span<const double> xyz) const {
    for (std::size_t k = 0; k + 2 < xyz.size(); k += 3) {
      if (!exact(&xyz[k])) return false;
    }
    return true;
  }
  Vec3 origin() const { return {centre_[0], centre_[1], centre_[2]}; }
  // All points of xyz (3 doubles each) in the frame.
  std::vector<float> convert(std::span<const double> xyz) const {
    std::vector<float> local(xyz.size());
    for (std::size_t k = 0; k < xyz.size(); ++k) {
      local[k] = static_cast<float>(xyz[k] - centre_[k % 3]);
    }
    return local;
  }

 private:
  // The origin on one axis for a box [lo, hi] (and a margin as wide again on each side, for
  // halos): 0 when that range reaches zero or lies near it for its width, else the range's
  // centre rounded to a multiple of float's step at the range's smallest magnitude. Either way a
  // coordinate read as float minus the origin is again a float, exactly: the mesher decides on
  // the very coordinates the output holds (its crossing test depends on it), while
  // georeferenced coordinates keep float's precision near the box. A range narrower than that
  // step (one value, a plane square to the axis far from zero) has its centre as the origin:
  // rounded to the step, it would leave the range up to half a step (3.4e7 at 1e15) from zero,
  // where float cannot tell its points apart and the crossing test's margins (relative to the
  // coordinates) swallow the spacing. Floats read from a file lie a step apart, so such a range
  // of them is one value, and minus the origin it is 0. Coordinates finer than float are rounded
  // here; exact() says so, and the crossing tests then read the input's own coordinates instead
  // (detail::CrossingPositions).
  static double origin(double lo, double hi) {
    const double width = hi - lo;
    const double near = std::min(std::abs(lo - width), std::abs(hi + width));
    if ((lo - width <= 0 && hi + width >= 0) || !(2 * width < near)) return 0;
    int exponent = 0;
    std::frexp(near, &exponent);  // near = f * 2^exponent, f in [0.5, 1)
    const double step = std::ldexp(1.0, exponent - 24);
    if (width < step) return lo + 0.5 * width;
    return std::round(0.5 * (lo + hi) / step) * step;
  }
  double centre_[3];
};

}  // namespace g2s
