// Separating planes (src/common/separating_planes.hpp) against the exact crossing test: they
// settle neighbours side by side (across a shared edge, beside at a corner, above the plane),
// never a pair that crosses or touches (folded flat, piercing, a corner on an edge or on the
// face), nor a triangle against itself; on 200k random pairs, flat, nearly coplanar and touching
// by a rounding, none they settle crosses, and they settle most that do not.
#include "common/separating_planes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "common/exact_predicates.hpp"
#include "common/triangle_intersection.hpp"

namespace g2s {
namespace {

std::array<Vec3, 3> corners(const std::vector<Vec3f>& points, const Triangle& t) {
  return {Vec3(points[t[0]]), Vec3(points[t[1]]), Vec3(points[t[2]])};
}
bool cross(const std::vector<Vec3f>& points, const Triangle& a, const Triangle& b) {
  const std::array<Vec3, 3> pa = corners(points, a), pb = corners(points, b);
  return triangles_cross(pa.data(), pb.data());
}
bool collinear(const std::vector<Vec3f>& points, const Triangle& t) {
  const std::array<Vec3, 3> p = corners(points, t);
  const double a[3] = {p[0].x, p[0].y, p[0].z}, b[3] = {p[1].x, p[1].y, p[1].z},
               c[3] = {p[2].x, p[2].y, p[2].z};
  return exact::collinear(a, b, c);
}

TEST(SeparatingPlanes, SettleNeighboursInOneSurfaceButNeverACrossing) {
  // A flat square's halves share the diagonal; a triangle beside it shares one corner; one lies
  // above the square apart; one is folded flat onto the first half; one pierces it; one touches
  // its edge with a corner (a crossing: a point in common that is not shared). The planes
  // decide nothing about the crossing ones nor the triangle itself.
  const std::vector<Vec3f> points = {{0, 0, 0},    {1, 0, 0},        {1, 1, 0},       {0, 1, 0},
                                     {2, 0, 0},    {2, 1, 0},        {0, 0, 1},       {1, 0, 1},
                                     {0.5f, 0, 0}, {0.7f, 0.2f, -1}, {0.7f, 0.2f, 1}, {0.5f, -1, 0},
                                     {0, 1, 1},    {0.7f, 0.2f, 0}};
  const Triangle half{0, 1, 2};
  const SeparatingPlanes planes(points, half);
  EXPECT_TRUE(planes.separate(points, {0, 2, 3}));    // the other half, across the shared edge
  EXPECT_TRUE(planes.separate(points, {1, 4, 5}));    // beside it, one shared corner
  EXPECT_TRUE(planes.separate(points, {6, 7, 12}));   // above its plane
  EXPECT_FALSE(planes.separate(points, {0, 2, 4}));   // folded flat onto it
  EXPECT_FALSE(planes.separate(points, {9, 10, 3}));  // piercing it
  EXPECT_FALSE(planes.separate(points, {8, 11, 4}));  // a corner on its edge 0-1
  EXPECT_FALSE(planes.separate(points, {6, 7, 13}));  // a corner on its face, the rest above
  EXPECT_FALSE(planes.separate(points, {2, 0, 1}));   // itself
  for (const Triangle& o : std::vector<Triangle>{{0, 2, 4}, {9, 10, 3}, {8, 11, 4}, {6, 7, 13}}) {
    EXPECT_TRUE(cross(points, half, o));
  }
}

TEST(SeparatingPlanes, NeverSeparateTrianglesThatCross) {
  // Pairs of small triangles about one point, flat and nearly coplanar (offsets down to 1e-7),
  // sharing 0, 1 or 2 corners, some touching: whenever the planes separate a pair, the exact test
  // must find no crossing; and they settle most pairs that do not cross.
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> unit(-1, 1);
  std::size_t separated = 0, apart = 0, crossing = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const float flat = trial % 3 == 0 ? 0.0f : trial % 3 == 1 ? 1e-7f : 0.3f;
    std::vector<Vec3f> points;
    for (int k = 0; k < 6; ++k) {
      const Vec3f p{100 + unit(rng), 50 + unit(rng), flat * unit(rng)};
      if (std::find_if(points.begin(), points.end(), [&](const Vec3f& q) {
            return q.x == p.x && q.y == p.y && q.z == p.z;
          }) != points.end()) {
        continue;
      }
      points.push_back(p);
    }
    if (points.size() < 6) continue;
    const Triangle a{0, 1, 2};
    if (trial % 5 == 4) {
      // b's first corner on a's edge 0-1 or inside a, as float rounding puts it: b touches a,
      // crosses it by a rounding or misses it by one.
      const float w = trial % 10 == 4 ? 0.0f : 0.25f;
      const auto mix = [&](float Vec3f::*axis) {
        return 0.45f * (points[0].*axis) + (0.55f - w) * (points[1].*axis) + w * (points[2].*axis);
      };
      points[3] = {mix(&Vec3f::x), mix(&Vec3f::y), mix(&Vec3f::z)};
    }
    const int shared = trial % 4 == 3 ? 0 : trial % 4;  // 0, 1, 2, 0
    Triangle b{3, 4, 5};
    if (shared >= 1) b[0] = 0;
    if (shared == 2) b[1] = 2;
    if (collinear(points, a) || collinear(points, b)) continue;
    const bool crosses = cross(points, a, b);
    const bool settled = SeparatingPlanes(points, a).separate(points, b);
    ASSERT_FALSE(crosses && settled) << "trial " << trial;
    crossing += crosses;
    apart += !crosses;
    separated += settled;
  }
  EXPECT_GT(crossing, 10000u);
  EXPECT_GT(separated, apart * 3 / 4);
}

TEST(SeparatingPlanes, DecideNothingWhereProductsCouldUnderOrOverflow) {
  // The other half of a square across the shared diagonal, in double: settled at scale 1, not
  // where coordinate differences fall below 1e-60 or above 1e60 (the margin would no longer
  // bound the rounding).
  for (const double scale : {1.0, 1e-70, 1e70}) {
    const std::vector<Vec3> points = {{0, 0, 0}, {scale, 0, 0}, {scale, scale, 0}, {0, scale, 0}};
    const auto position = [&](Index v) { return points[v]; };
    const SeparatingPlanes planes(Triangle{0, 1, 2}, position);
    EXPECT_EQ(planes.separate(Triangle{0, 2, 3}, position), scale == 1.0) << scale;
  }
}

}  // namespace
}  // namespace g2s
