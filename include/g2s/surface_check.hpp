// Whether a cloud can make a surface at all, asked before meshing so that the CLI can say why
// nothing was written instead of producing an empty or sliver-only mesh (src/check/).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "g2s/types.hpp"

namespace g2s {

// Why the points of `cloud` cannot form any surface, or "" when they can. A surface needs three
// distinct points that are not on one straight line; the answer names the case: no points, all
// points the same, only two distinct points, all points on one line, or (as the mesher works in
// float) a cloud wider than 1e38 along an axis. "On one line" allows for float rounding (the
// mesher works in float): every point within 1e-6 of the cloud's length of the line through two
// points about a diameter apart (found by two farthest-point sweeps), all but one stray point
// allowed when ten or more are on the line. Linear time; only the collinear case allocates (to
// count distinct points).
std::string why_no_surface(const PointCloud& cloud);

// The same for `n` points visited by `each`, which calls its argument with runs of points (x,
// y, z each) holding every point, in the same order each time, e.g. a tile store's tiles loaded
// one at a time. Real clouds take one pass (four points on it that no line holds three of
// settle them); a line or nearly one up to seven and a copy.
using PointRun = std::function<void(std::span<const double>)>;
using PointVisitor = std::function<void(const PointRun&)>;
std::string why_no_surface(std::uint64_t n, const PointVisitor& each);

// The part of that check a bounding box answers (the tile store asks it before writing): why
// points in [lo, hi] are beyond float's range (wider than 1e38, or narrower than 1e-30 along
// every axis but not a single point), or "".
std::string why_beyond_float(const double lo[3], const double hi[3]);

}  // namespace g2s
