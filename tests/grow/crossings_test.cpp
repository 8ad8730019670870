// The grower's search for crossing triangles (src/grow/crossings.hpp): TriangleCells must find
// exactly the pairs a test of every pair finds, on soups of small and large triangles where
// many cross, and for_each_near must report every triangle whose box overlaps the query.
#include "grow/crossings.hpp"

#include <gtest/gtest.h>

#include <random>

namespace g2s {
namespace {

struct Soup {
  std::vector<Vec3f> points;
  std::vector<Triangle> triangles;
};

// Triangles with corners near random centres; one in `large_every` is many times larger.
Soup random_soup(std::size_t count, int large_every, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> where(0, 10), offset(-0.6f, 0.6f);
  Soup soup;
  for (std::size_t t = 0; t < count; ++t) {
    const float scale = (large_every > 0 && t % static_cast<std::size_t>(large_every) == 0) ? 8 : 1;
    const Vec3f c{where(rng), where(rng), where(rng) * 0.1f};
    const auto first = static_cast<Index>(soup.points.size());
    for (int k = 0; k < 3; ++k) {
      soup.points.push_back(
          {c.x + scale * offset(rng), c.y + scale * offset(rng), c.z + scale * offset(rng) * 0.3f});
    }
    // Every third triangle shares a corner with the one before: shared corners are exercised.
    Triangle tri{first, first + 1, first + 2};
    if (t % 3 == 2) tri[0] = first - 1;
    soup.triangles.push_back(tri);
  }
  return soup;
}

TEST(Crossings, CellsFindExactlyThePairsOfABruteForceSearch) {
  for (const int large_every : {0, 7}) {
    const Soup soup = random_soup(600, large_every, 11u + static_cast<unsigned>(large_every));
    std::vector<std::pair<std::uint32_t, std::uint32_t>> expected;
    for (std::uint32_t s = 0; s < soup.triangles.size(); ++s) {
      for (std::uint32_t t = s + 1; t < soup.triangles.size(); ++t) {
        if (detail::triangles_cross(soup.points, soup.triangles[s], soup.triangles[t])) {
          expected.push_back({s, t});
        }
      }
    }
    ASSERT_GT(expected.size(), 50u) << "the soup must cross itself to test anything";
    const detail::TriangleCells cells(soup.points, soup.triangles);
    const auto found = cells.crossing_pairs([](std::uint32_t) { return false; },
                                            [](std::uint32_t) { return true; });
    EXPECT_EQ(found, expected);
    // Focus on one triangle: only its pairs.
    const std::uint32_t focus = expected.front().first;
    const auto focused = cells.crossing_pairs([](std::uint32_t) { return false; },
                                              [&](std::uint32_t t) { return t == focus; });
    for (const auto& [s, t] : focused) EXPECT_TRUE(s == focus || t == focus);
    EXPECT_FALSE(focused.empty());
  }
}

TEST(Crossings, SharedEdgesAndCornersAreNotCrossings) {
  // Two triangles of a flat square sharing the diagonal; a third sharing one corner, beside.
  const std::vector<Vec3f> points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0},
                                     {0, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  EXPECT_FALSE(detail::triangles_cross(points, {0, 1, 2}, {0, 2, 3}));
  EXPECT_FALSE(detail::triangles_cross(points, {0, 1, 2}, {1, 4, 5}));
  // Folded flat onto each other across the shared edge 0-2: they overlap.
  EXPECT_TRUE(detail::triangles_cross(points, {0, 1, 2}, {0, 2, 4}));
  // A triangle piercing the square's first half.
  const std::vector<Vec3f> pierce = {{0, 0, 0},        {1, 0, 0},       {1, 1, 0},
                                     {0.7f, 0.2f, -1}, {0.7f, 0.2f, 1}, {0.9f, 0.3f, 1}};
  EXPECT_TRUE(detail::triangles_cross(pierce, {0, 1, 2}, {3, 4, 5}));
}

}  // namespace
}  // namespace g2s
