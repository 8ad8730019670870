// The least-area triangulation of a hole's loop (src/grow/hole_filling.hpp) on loops whose
// answers are known: a planar convex loop gives n - 2 triangles covering exactly its area, all
// facing one way; forbidden chords are never used; a loop that can only be closed with
// forbidden chords, or only with degenerate triangles, is left open.
#include "grow/hole_filling.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace g2s {
namespace {

std::vector<Vec3f> regular_polygon(int n) {
  std::vector<Vec3f> points;
  for (int k = 0; k < n; ++k) {
    const double angle = 2 * std::numbers::pi * k / n;
    points.push_back({static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)), 0});
  }
  return points;
}

std::vector<Index> identity_loop(int n) {
  std::vector<Index> loop(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) loop[static_cast<std::size_t>(k)] = static_cast<Index>(k);
  return loop;
}

TEST(HoleFilling, ConvexLoopIsCoveredOnceFacingOneWay) {
  for (const int n : {3, 4, 6, 11, 30}) {
    const std::vector<Vec3f> points = regular_polygon(n);
    const std::vector<Index> loop = identity_loop(n);
    detail::HoleScratch scratch;
    std::vector<Triangle> out;
    ASSERT_TRUE(detail::triangulate_loop(
        points, loop, [](std::size_t, std::size_t) { return true; }, scratch, out));
    ASSERT_EQ(out.size(), static_cast<std::size_t>(n - 2));
    double area = 0;
    for (const Triangle& t : out) {
      const Vec3 a(points[t[0]]), b(points[t[1]]), c(points[t[2]]);
      const Vec3 normal = cross(b - a, c - a);
      EXPECT_GT(normal.z, 0) << "counter-clockwise along the loop";
      area += 0.5 * normal.z;
    }
    const double expected = 0.5 * n * std::sin(2 * std::numbers::pi / n);
    EXPECT_NEAR(area, expected, 1e-5 * expected) << n << " corners";
  }
}

TEST(HoleFilling, ForbiddenChordsAreNeverUsed) {
  const std::vector<Vec3f> points = regular_polygon(8);
  const std::vector<Index> loop = identity_loop(8);
  // Only chords from corner 0 are allowed: the answer is the fan around 0.
  const auto from_zero = [](std::size_t i, std::size_t) { return i == 0; };
  detail::HoleScratch scratch;
  std::vector<Triangle> out;
  ASSERT_TRUE(detail::triangulate_loop(points, loop, from_zero, scratch, out));
  for (const Triangle& t : out) {
    EXPECT_EQ(t[0], 0u) << "every triangle of the fan has corner 0 first";
  }
}

TEST(HoleFilling, LoopThatNeedsAForbiddenChordStaysOpen) {
  const std::vector<Vec3f> points = regular_polygon(4);
  const std::vector<Index> loop = identity_loop(4);
  detail::HoleScratch scratch;
  std::vector<Triangle> out;
  EXPECT_FALSE(detail::triangulate_loop(
      points, loop, [](std::size_t, std::size_t) { return false; }, scratch, out));
  EXPECT_TRUE(out.empty());
}

TEST(HoleFilling, CollinearLoopStaysOpen) {
  const std::vector<Vec3f> points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  const std::vector<Index> loop = identity_loop(4);
  detail::HoleScratch scratch;
  std::vector<Triangle> out;
  EXPECT_FALSE(detail::triangulate_loop(
      points, loop, [](std::size_t, std::size_t) { return true; }, scratch, out));
}

}  // namespace
}  // namespace g2s
