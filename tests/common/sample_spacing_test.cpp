// Tests of the spacing rule (src/common/sample_spacing.hpp): evenly sampled clouds, random or
// regular, in a plane, along lines or in a volume, keep exactly their nearest-neighbour
// distances; clouds whose points come with near-copies are measured past the copies.
#include "common/sample_spacing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

using g2s::NearestThree;
using g2s::spacing_distances;
using Point = std::array<double, 3>;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Brute force: every point's three nearest other points at another position.
std::vector<NearestThree> nearest_three(const std::vector<Point>& points) {
  std::vector<NearestThree> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = 0; j < points.size(); ++j) {
      const double d = std::hypot(points[i][0] - points[j][0], points[i][1] - points[j][1],
                                  points[i][2] - points[j][2]);
      if (d > 0) out[i].offer(d);
    }
  }
  return out;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

struct Cloud {
  std::string name;
  std::vector<Point> points;
};

std::vector<Cloud> evenly_sampled() {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Cloud> clouds(6);
  clouds[0].name = "square lattice";
  clouds[1].name = "one line";
  clouds[2].name = "scan lines ten steps apart";
  clouds[3].name = "random plane";
  clouds[4].name = "random volume";
  clouds[5].name = "noisy plane (a layer thicker than its spacing)";
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) clouds[0].points.push_back({0.5 * i, 0.5 * j, 0.0});
  }
  for (int i = 0; i < 1000; ++i) clouds[1].points.push_back({0.1 * i, 0.2 * i, 0.0});
  for (int line = 0; line < 10; ++line) {
    for (int i = 0; i < 150; ++i) clouds[2].points.push_back({0.01 * i, 0.1 * line, 0.0});
  }
  for (int i = 0; i < 1500; ++i) {
    clouds[3].points.push_back({u(rng), u(rng), 0.0});
    clouds[4].points.push_back({u(rng), u(rng), u(rng)});
    clouds[5].points.push_back({u(rng), u(rng), 0.05 * g(rng)});
  }
  return clouds;
}

TEST(SampleSpacing, NearestThreeKeepsTheThreeSmallestInOrder) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int n = 0; n < 8; ++n) {
    std::vector<double> offered;
    NearestThree near;
    for (int k = 0; k < n; ++k) {
      offered.push_back(k == 3 ? offered[1] : u(rng));  // a tie too
      near.offer(offered.back());
    }
    near.offer(std::numeric_limits<double>::quiet_NaN());  // never kept
    std::sort(offered.begin(), offered.end());
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(near.d[k], k < offered.size() ? offered[k] : kInf) << n << " offered";
    }
  }
}

// Every evenly sampled cloud keeps its nearest-neighbour distances, exactly and in order: the
// rule changes nothing where there are no twins.
TEST(SampleSpacing, EvenlySampledCloudsKeepTheirNearestDistances) {
  for (const Cloud& cloud : evenly_sampled()) {
    const std::vector<NearestThree> samples = nearest_three(cloud.points);
    const g2s::SpacingDistances out = spacing_distances(samples);
    EXPECT_EQ(out.twin_distance, 0.0) << cloud.name;
    std::vector<double> nearest;
    for (const NearestThree& s : samples) nearest.push_back(s.d[0]);
    EXPECT_EQ(out.distances, nearest) << cloud.name;
  }
}

// A random plane with near-copies of most or all of its points (one or two copies each, at
// 1/1000 or 1/20 of its spacing): the spacing is the plane's own, within 10%, and the copies are
// merged, within a distance between their offsets and the spacing.
TEST(SampleSpacing, CloudsOfTwinsAreMeasuredPastTheCopies) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Point> plane;
  for (int i = 0; i < 1500; ++i) plane.push_back({u(rng), u(rng), 0.0});
  std::vector<double> alone;
  for (const NearestThree& s : nearest_three(plane)) alone.push_back(s.d[0]);
  const double spacing = median(alone);
  std::normal_distribution<double> g(0.0, 1.0);
  for (const int copies : {1, 2}) {
    for (const double share : {0.6, 1.0}) {
      for (const double offset : {1e-3, 0.05}) {
        std::vector<Point> cloud = plane;
        for (std::size_t i = 0; i < plane.size(); ++i) {
          if (u(rng) >= share) continue;
          for (int c = 0; c < copies; ++c) {
            const double o = offset * spacing;
            cloud.push_back({plane[i][0] + o * g(rng), plane[i][1] + o * g(rng), o * g(rng)});
          }
        }
        const g2s::SpacingDistances out = spacing_distances(nearest_three(cloud));
        const std::string what = std::to_string(copies) + " copies of " + std::to_string(share) +
                                 " of the points, " + std::to_string(offset) + " spacing off";
        EXPECT_GT(out.twin_distance, 3 * offset * spacing) << what;
        EXPECT_LT(out.twin_distance, spacing) << what;
        EXPECT_NEAR(median(out.distances), spacing, 0.1 * spacing) << what;
      }
    }
  }
}

// Points in pairs 0.15 of the spacing apart (between the merge's eighth and the rule's quarter of
// the third-nearest distance): measured between the pairs, which are not merged.
TEST(SampleSpacing, LoosePairsAreMeasuredBetweenThePairsAndNotMerged) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Point> plane;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) plane.push_back({i + 0.2 * u(rng), j + 0.2 * u(rng), 0.0});
  }
  std::vector<Point> cloud = plane;
  for (const Point& p : plane) {
    const double a = 6.283185307179586 * u(rng);
    cloud.push_back({p[0] + 0.15 * std::cos(a), p[1] + 0.15 * std::sin(a), 0.0});
  }
  const g2s::SpacingDistances out = spacing_distances(nearest_three(cloud));
  EXPECT_EQ(out.twin_distance, 0.0);
  EXPECT_GT(median(out.distances), 0.6);  // the pairs' own 0.15 left behind
  EXPECT_LT(median(out.distances), 1.0);
}

// Samples with fewer than three neighbours within reach give no scale to compare with: their
// nearest distances are kept, however small.
TEST(SampleSpacing, WithoutThirdNeighboursTheNearestDistancesStand) {
  std::vector<NearestThree> samples(9);
  for (NearestThree& s : samples) s.offer(1e-6);
  samples[0].offer(1.0);
  samples[0].offer(2.0);
  const g2s::SpacingDistances out = spacing_distances(samples);
  EXPECT_EQ(out.twin_distance, 0.0);
  EXPECT_EQ(out.distances, std::vector<double>(9, 1e-6));
  EXPECT_TRUE(spacing_distances(std::vector<NearestThree>(3)).distances.empty());
}

}  // namespace
