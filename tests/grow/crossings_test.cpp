// The grower's search for crossing triangles (src/grow/crossings.hpp): TriangleCells must find
// exactly the pairs a test of every pair finds, on soups of small and large triangles where
// many cross, and for_each_near must report every triangle whose box overlaps the query.
#include "grow/crossings.hpp"

#include <gtest/gtest.h>

#include <random>

#include "grid/hash_grid.hpp"

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
    // Most large ones 8 times, one in five of them 60 times: three levels of cells at least.
    const auto every = static_cast<std::size_t>(large_every);
    const float scale =
        large_every > 0 && t % every == 0 ? (t % (5 * every) == 0 ? 60.0f : 8.0f) : 1.0f;
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
    EXPECT_EQ(cells.crossing_pairs(), expected);
    // Focused on some triangles: exactly the pairs that involve one of them.
    std::vector<std::uint32_t> focus;
    for (std::uint32_t t = 0; t < soup.triangles.size(); t += 5) focus.push_back(t);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> involving;
    for (const auto& [s, t] : expected) {
      if (s % 5 == 0 || t % 5 == 0) involving.push_back({s, t});
    }
    ASSERT_FALSE(involving.empty());
    EXPECT_EQ(cells.crossing_pairs_involving(focus), involving);
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

TEST(Crossings, TrianglesInEmptyBallsNeverCrossEachOther) {
  // Every triangle of nearby corners in a random cloud; those certified by an empty ball must
  // be pairwise free of crossings, while the rest cross plenty.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> where(0, 1);
  std::vector<float> xyz;
  for (int i = 0; i < 3 * 120; ++i) xyz.push_back(where(rng));
  const HashGrid grid(xyz, {});
  std::vector<Triangle> triangles;
  for (Index a = 0; a < grid.size(); ++a) {
    for (Index b = a + 1; b < grid.size(); ++b) {
      for (Index c = b + 1; c < grid.size(); ++c) {
        const auto near = [&](Index u, Index v) {
          return norm2(grid.position(u) - grid.position(v)) < 0.09;
        };
        if (near(a, b) && near(b, c) && near(a, c)) triangles.push_back({a, b, c});
      }
    }
  }
  std::size_t crossings = 0;
  for (std::size_t s = 0; s < triangles.size(); ++s) {
    for (std::size_t t = s + 1; t < triangles.size(); ++t) {
      crossings += detail::triangles_cross(grid.points(), triangles[s], triangles[t]);
    }
  }
  EXPECT_GT(crossings, 100u);
  // Every point a vertex, then one point in four left out (no triangle uses it, and it does
  // not count against a ball).
  std::vector<std::uint8_t> three_in_four(grid.size());
  for (Index v = 0; v < grid.size(); ++v) three_in_four[v] = v % 4 != 0;
  for (const std::vector<std::uint8_t>& vertex : {std::vector<std::uint8_t>{}, three_in_four}) {
    std::vector<Triangle> certified;
    for (const Triangle& t : triangles) {
      const bool uses_vertices = vertex.empty() || (vertex[t[0]] && vertex[t[1]] && vertex[t[2]]);
      if (uses_vertices && detail::in_empty_ball(grid, t, vertex)) certified.push_back(t);
    }
    ASSERT_GT(certified.size(), 80u);
    ASSERT_LT(certified.size(), triangles.size() / 2);
    for (std::size_t s = 0; s < certified.size(); ++s) {
      for (std::size_t t = s + 1; t < certified.size(); ++t) {
        EXPECT_FALSE(detail::triangles_cross(grid.points(), certified[s], certified[t]));
      }
    }
  }
}

TEST(Crossings, AFourthPointOnTheSphereDeniesTheCertificate) {
  // A square's corners lie on one circle: either diagonal's triangles could be Delaunay, and the
  // two splits overlap, so no triangle of them may be certified. A point nudged off the circle
  // decides it.
  const std::vector<float> square = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const HashGrid on_circle(square, {});
  for (const Triangle& t : {Triangle{0, 1, 2}, Triangle{0, 2, 3}, Triangle{0, 1, 3}}) {
    EXPECT_FALSE(detail::in_empty_ball(on_circle, t, {}));
  }
  // A fourth point that is no vertex (left out of the mesh) does not count.
  for (Index left_out = 0; left_out < 4; ++left_out) {
    std::vector<std::uint8_t> vertex(4, 1);
    vertex[left_out] = 0;
    Triangle t;
    for (Index k = 0, n = 0; k < 4; ++k) {
      if (k != left_out) t[n++] = k;
    }
    EXPECT_TRUE(detail::in_empty_ball(on_circle, t, vertex));
  }
  std::vector<float> kite = square;
  kite[10] = 1.01f;  // the fourth corner just outside the circle of the first three
  const HashGrid off_circle(kite, {});
  Index at[4];  // grid index of each input point
  for (Index i = 0; i < 4; ++i) at[off_circle.source(i)] = i;
  EXPECT_TRUE(detail::in_empty_ball(off_circle, {at[0], at[1], at[2]}, {}));
  EXPECT_TRUE(detail::in_empty_ball(off_circle, {at[0], at[2], at[3]}, {}));
  EXPECT_FALSE(detail::in_empty_ball(off_circle, {at[0], at[1], at[3]}, {}));
  EXPECT_FALSE(detail::in_empty_ball(off_circle, {at[1], at[2], at[3]}, {}));
}

}  // namespace
}  // namespace g2s
