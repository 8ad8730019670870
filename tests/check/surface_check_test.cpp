// why_no_surface (src/check/): the clouds no surface can be made of are named, and anything with
// three points off one line, a flat or a thin one included, is left to the mesher.
#include "g2s/surface_check.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

using g2s::PointCloud;
using g2s::why_no_surface;

PointCloud cloud_of(std::initializer_list<double> xyz) {
  return PointCloud{std::vector<double>(xyz)};
}

bool says(const std::string& reason, const std::string& words) {
  return reason.find(words) != std::string::npos;
}

TEST(SurfaceCheck, EmptyAndSinglePointClouds) {
  EXPECT_TRUE(says(why_no_surface(PointCloud{}), "no points"));
  EXPECT_TRUE(says(why_no_surface(cloud_of({1, 2, 3})), "single point"));
}

TEST(SurfaceCheck, RepeatedPointIsOnePoint) {
  EXPECT_TRUE(says(why_no_surface(cloud_of({1, 2, 3, 1, 2, 3, 1, 2, 3})), "all 3 points"));
}

TEST(SurfaceCheck, TwoDistinctPointsHoweverRepeated) {
  EXPECT_TRUE(says(why_no_surface(cloud_of({0, 0, 0, 1, 1, 1})), "only 2 distinct points"));
  EXPECT_TRUE(says(why_no_surface(cloud_of({0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1})),
                   "only 2 distinct points (4 in all)"));
}

// Points a float rounding away from a line are on it for the mesher.
TEST(SurfaceCheck, CollinearWithinFloatRounding) {
  PointCloud line;
  for (int i = 0; i < 1000; ++i) {
    const double t = 1e3 + 0.01 * i;
    const double wobble = (i % 2 ? 1 : -1) * 1e-9;
    line.xyz.insert(line.xyz.end(), {t, 2 * t + wobble, -t});
  }
  EXPECT_TRUE(
      says(why_no_surface(line), "all 1000 points (1000 distinct) lie on one straight line"));
}

// Beyond float range the mesher would see infinities; here squared distances would overflow.
TEST(SurfaceCheck, CoordinatesBeyondFloatRange) {
  EXPECT_TRUE(says(why_no_surface(cloud_of({0, 0, 0, 1, 0, 0, 0, 1, 0, 1e300, 0, 0})),
                   "the points span 1e+300 along x"));
  EXPECT_TRUE(says(why_no_surface(cloud_of({0, 0, 0, 1, 0, 0, 0, -1e200, 1})), "along y"));
}

// Below float's normal range the mesher's float coordinates lose their precision: a torus of
// 800 points scaled by 1e-44 came out with crossing triangles, at 1e-100 "too sparse", at 1e-250
// (squared distances underflow in double) "the same point".
TEST(SurfaceCheck, CloudsTooSmallForFloatAreNamed) {
  for (const double scale : {1e-44, 1e-100, 1e-250}) {
    const PointCloud tiny =
        cloud_of({0, 0, 0, 3 * scale, 0, 0, 0, 2 * scale, 0, 0, 0, scale, scale, scale, scale});
    EXPECT_TRUE(says(why_no_surface(tiny), "too small for the float coordinates")) << scale;
  }
  EXPECT_EQ(why_no_surface(cloud_of({0, 0, 0, 3e-29, 0, 0, 0, 2e-29, 0})), "");
  EXPECT_TRUE(says(why_no_surface(cloud_of({1e-40, 0, 0, 1e-40, 0, 0})), "all 2 points"));
}

TEST(SurfaceCheck, ThreePointsOffALineCanMakeASurface) {
  EXPECT_EQ(why_no_surface(cloud_of({0, 0, 0, 1, 0, 0, 0, 1, 0})), "");
}

// A long thin strip (width 1e-4 of its length) and a flat grid are surfaces.
TEST(SurfaceCheck, ThinStripAndFlatCloudCanMakeASurface) {
  PointCloud strip;
  for (int i = 0; i < 100; ++i) {
    for (int row = 0; row < 2; ++row) strip.xyz.insert(strip.xyz.end(), {i * 1.0, row * 1e-2, 0});
  }
  EXPECT_EQ(why_no_surface(strip), "");
  PointCloud flat;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) flat.xyz.insert(flat.xyz.end(), {i * 1.0, j * 1.0, 7.0});
  }
  EXPECT_EQ(why_no_surface(flat), "");
}

// The passes over a tile store are the check's cost before meshing: a real cloud is settled by
// the first pass, and a line with one stray point still takes the passes that find the stray.
TEST(SurfaceCheck, RealCloudTakesOnePass) {
  PointCloud flat;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) flat.xyz.insert(flat.xyz.end(), {i * 1.0, j * 1e-3, 7.0});
  }
  PointCloud stray;
  for (int i = 0; i < 100; ++i) stray.xyz.insert(stray.xyz.end(), {i * 1.0, 2.0 * i, 3.0});
  stray.xyz.insert(stray.xyz.end(), {50.0, 0.0, 3.0});
  const auto passes = [](const PointCloud& cloud, std::string& why) {
    int count = 0;
    why = why_no_surface(cloud.size(), [&](const g2s::PointRun& visit) {
      ++count;
      visit(cloud.xyz);
    });
    return count;
  };
  std::string why;
  EXPECT_EQ(passes(flat, why), 1);
  EXPECT_EQ(why, "");
  EXPECT_GT(passes(stray, why), 1);
  EXPECT_TRUE(says(why, "lie on one straight line")) << why;
  EXPECT_TRUE(says(why, "but the one at (50, 0, 3)")) << why;
}

}  // namespace
