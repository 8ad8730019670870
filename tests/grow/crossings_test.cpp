// The grower's tests for crossing triangles (src/grow/crossings.hpp): CrossingGuard must refuse
// exactly the triangles that a test against every triangle made before refuses, TriangleCells
// must find exactly the pairs a test of every pair finds, and TriangleCells with separating
// planes exactly the triangles a new one crosses, on soups of small and large triangles where
// many cross, on every triangle of nearby points in a random cloud, and where four points lie on
// one circle; and, given coordinates finer than float, both judge on those (a crossing the
// floats hide is refused).
#include "grow/crossings.hpp"

#include <gtest/gtest.h>

#include <random>

#include "common/exact_predicates.hpp"
#include "common/separating_planes.hpp"
#include "common/triangle_intersection.hpp"
#include "grid/hash_grid.hpp"

namespace g2s {
namespace {

using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

// A grid of the points, and the triangles renumbered to its indices.
struct Soup {
  HashGrid grid;
  std::vector<Triangle> triangles;
};

Soup soup_of(const std::vector<float>& xyz, std::vector<Triangle> triangles) {
  Soup soup{HashGrid(xyz, {}), std::move(triangles)};
  std::vector<Index> at(soup.grid.size());  // grid index of each input point
  for (Index i = 0; i < soup.grid.size(); ++i) at[soup.grid.source(i)] = i;
  for (Triangle& t : soup.triangles) {
    for (Index& v : t) v = at[v];
  }
  return soup;
}

// Triangles with corners near random centres; one in `large_every` is many times larger.
Soup random_soup(std::size_t count, int large_every, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> where(0, 10), offset(-0.6f, 0.6f);
  std::vector<float> xyz;
  std::vector<Triangle> triangles;
  for (std::size_t t = 0; t < count; ++t) {
    const auto every = static_cast<std::size_t>(large_every);
    const float scale =
        large_every > 0 && t % every == 0 ? (t % (5 * every) == 0 ? 60.0f : 8.0f) : 1.0f;
    const float c[3] = {where(rng), where(rng), where(rng) * 0.1f};
    const auto first = static_cast<Index>(xyz.size() / 3);
    for (int k = 0; k < 3; ++k) {
      xyz.push_back(c[0] + scale * offset(rng));
      xyz.push_back(c[1] + scale * offset(rng));
      xyz.push_back(c[2] + scale * offset(rng) * 0.3f);
    }
    // Every third triangle shares a corner with the one before: shared corners are exercised.
    Triangle tri{first, first + 1, first + 2};
    if (t % 3 == 2) tri[0] = first - 1;
    triangles.push_back(tri);
  }
  return soup_of(xyz, std::move(triangles));
}

Pairs brute_force_pairs(const Soup& soup) {
  Pairs pairs;
  for (std::uint32_t s = 0; s < soup.triangles.size(); ++s) {
    for (std::uint32_t t = s + 1; t < soup.triangles.size(); ++t) {
      if (detail::triangles_cross(soup.grid.points(), soup.triangles[s], soup.triangles[t])) {
        pairs.push_back({s, t});
      }
    }
  }
  return pairs;
}

// The triangles refused when each is asked about in turn and the others made, the first `fixed`
// made without asking (a seam's preload): by a guard, or by a test against every one made.
std::vector<std::uint32_t> refusals(const Soup& soup, std::size_t fixed, bool brute_force) {
  const detail::CrossingPositions positions(soup.grid);
  detail::CrossingGuard guard(soup.grid, positions);
  std::vector<Triangle> made;
  std::vector<std::uint32_t> refused;
  for (std::uint32_t t = 0; t < soup.triangles.size(); ++t) {
    const Triangle& tri = soup.triangles[t];
    bool crosses = false;
    if (t >= fixed && brute_force) {
      for (const Triangle& o : made) {
        crosses = crosses || detail::triangles_cross(soup.grid.points(), tri, o);
      }
    } else if (t >= fixed) {
      crosses = guard.crosses(tri, made);
    }
    if (crosses) {
      refused.push_back(t);
      continue;
    }
    made.push_back(tri);
    guard.file(static_cast<std::uint32_t>(made.size() - 1), made);
  }
  return refused;
}

// Whether triangle t crosses a filed triangle, as the grower's hole filling asks: the filed
// triangles whose boxes overlap t's, t's separating planes, then the exact test.
bool cells_say_crosses(const Soup& soup, const detail::TriangleCells& cells,
                       std::span<const Triangle> filed, const Triangle& t) {
  Vec3f lo = soup.grid.point(t[0]), hi = lo;
  for (const Index v : t) {
    const Vec3f& p = soup.grid.point(v);
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const SeparatingPlanes planes(soup.grid.points(), t);
  bool crosses = false;
  cells.for_each_near(lo, hi, [&](std::uint32_t other, const detail::Box&) {
    const Triangle& o = filed[other];
    crosses = crosses || (!planes.separate(soup.grid.points(), o) &&
                          detail::triangles_cross(soup.grid.points(), t, o));
  });
  return crosses;
}

TEST(Crossings, TheGuardAndTheCellsAnswerAsATestOfEveryPair) {
  for (const int large_every : {0, 7}) {
    const Soup soup = random_soup(600, large_every, 11u + static_cast<unsigned>(large_every));
    const Pairs expected = brute_force_pairs(soup);
    ASSERT_GT(expected.size(), 50u) << "the soup must cross itself to test anything";
    const std::vector<std::uint32_t> refused = refusals(soup, 0, true);
    ASSERT_GT(refused.size(), 30u);
    EXPECT_EQ(refusals(soup, 0, false), refused);
    EXPECT_EQ(detail::TriangleCells(soup.grid.points(), soup.triangles)
                  .crossing_pairs(detail::CrossingPositions(soup.grid)),
              expected);
  }
}

// Triangles made without asking (a seam's preload, which may cross itself) still refuse every
// later triangle that crosses them.
TEST(Crossings, TrianglesMadeWithoutAskingAreGuardedAgainst) {
  for (const int large_every : {0, 7}) {
    const Soup soup = random_soup(600, large_every, 5u + static_cast<unsigned>(large_every));
    for (const std::size_t fixed : {std::size_t{150}, std::size_t{450}}) {
      const std::vector<std::uint32_t> refused = refusals(soup, fixed, true);
      ASSERT_GT(refused.size(), 10u);
      EXPECT_EQ(refusals(soup, fixed, false), refused) << fixed;
    }
  }
}

TEST(Crossings, CellsWithSeparatingPlanesFindEveryTriangleANewOneCrosses) {
  // Two triangles in three filed; new triangles of their corners (an edge of a filed triangle
  // with the corner nearest its centre) ask whether they cross one.
  for (const int large_every : {0, 7}) {
    const Soup soup = random_soup(600, large_every, 3u + static_cast<unsigned>(large_every));
    std::vector<Triangle> filed;
    for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
      if (t % 3 != 1) filed.push_back(soup.triangles[t]);
    }
    const detail::TriangleCells cells(soup.grid.points(), filed);
    std::size_t crossing = 0, clear = 0;
    for (const Triangle& from : filed) {
      const Vec3 centre = (soup.grid.position(from[0]) + soup.grid.position(from[1]) +
                           soup.grid.position(from[2])) *
                          (1.0 / 3);
      Index nearest = kNoIndex;
      for (const Triangle& other : filed) {
        for (const Index v : other) {
          if (std::find(from.begin(), from.end(), v) != from.end()) continue;
          if (nearest == kNoIndex ||
              norm2(soup.grid.position(v) - centre) < norm2(soup.grid.position(nearest) - centre)) {
            nearest = v;
          }
        }
      }
      const Triangle tri{from[0], from[1], nearest};
      if (detail::degenerate(soup.grid.points(), tri)) continue;
      bool expect = false;
      for (const Triangle& o : filed) {
        expect = expect || detail::triangles_cross(soup.grid.points(), tri, o);
      }
      EXPECT_EQ(cells_say_crosses(soup, cells, filed, tri), expect);
      crossing += expect;
      clear += !expect;
    }
    EXPECT_GT(crossing, 10u);
    EXPECT_GT(clear, 10u);
  }
}

TEST(Crossings, ASliverHasNoCircumballAndIsRefused) {
  // A sliver under 0.006 degrees, folded flat onto its neighbour across their shared edge: the
  // pair crosses, but the sliver has no circumball for the guard's argument (the grower never
  // makes one), so the guard refuses it whatever it crosses.
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0.5f, 1e-7f, 0, 0.5f, 1, 0};
  const Soup soup = soup_of(xyz, {{0, 1, 3}, {0, 1, 2}});
  const Triangle& sliver = soup.triangles[1];
  EXPECT_FALSE(has_circumball(soup.grid.position(sliver[0]), soup.grid.position(sliver[1]),
                              soup.grid.position(sliver[2])));
  ASSERT_FALSE(detail::degenerate(soup.grid.points(), sliver));
  ASSERT_TRUE(detail::triangles_cross(soup.grid.points(), soup.triangles[0], sliver));
  const detail::CrossingPositions positions(soup.grid);
  detail::CrossingGuard guard(soup.grid, positions);
  EXPECT_TRUE(guard.crosses(sliver, {}));
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

TEST(Crossings, EveryCrossingAmongTheTrianglesOfACloudIsFound) {
  // Every triangle of nearby points in a random cloud: they cross plenty, and the guard refuses
  // exactly what a test against every triangle made refuses. Then with one point in four left
  // out (no triangle uses it, and it must not count against a ball).
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> where(0, 1);
  std::vector<float> xyz;
  for (int i = 0; i < 3 * 120; ++i) xyz.push_back(where(rng));
  const auto near = [&](Index u, Index v) {
    float d2 = 0;
    for (int k = 0; k < 3; ++k)
      d2 += (xyz[3 * u + k] - xyz[3 * v + k]) * (xyz[3 * u + k] - xyz[3 * v + k]);
    return d2 < 0.09f;
  };
  for (const Index skip : {Index{0}, Index{4}}) {
    std::vector<Triangle> triangles;
    for (Index a = 0; a < 120; ++a) {
      for (Index b = a + 1; b < 120; ++b) {
        for (Index c = b + 1; c < 120; ++c) {
          const bool used = skip == 0 || (a % skip != 0 && b % skip != 0 && c % skip != 0);
          if (used && near(a, b) && near(b, c) && near(a, c)) triangles.push_back({a, b, c});
        }
      }
    }
    const Soup soup = soup_of(xyz, std::move(triangles));
    const std::vector<std::uint32_t> refused = refusals(soup, 0, true);
    EXPECT_GT(refused.size(), 50u);
    EXPECT_EQ(refusals(soup, 0, false), refused);
  }
}

TEST(Crossings, FourPointsOnOneCircleAreSearched) {
  // A square's corners lie on one circle: each of its four triangles has the fourth corner on
  // its ball's sphere, and the two ways to split the square overlap. A point exactly on the
  // sphere must count as inside, or the overlaps would go unsearched: one split is made, both
  // triangles of the other refused.
  const std::vector<float> square = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const std::vector<Triangle> four = {{0, 1, 2}, {0, 2, 3}, {0, 1, 3}, {1, 2, 3}};
  const Soup soup = soup_of(square, four);
  ASSERT_EQ(brute_force_pairs(soup).size(), 4u);  // each split against each triangle of the other
  EXPECT_EQ(refusals(soup, 0, false), (std::vector<std::uint32_t>{2, 3}));
  EXPECT_EQ(refusals(soup, 0, true), (std::vector<std::uint32_t>{2, 3}));
}

// Coordinates finer than float (a double PLY, a LAS file): a triangle whose corner pierces another
// by less than float's rounding crosses it in the coordinates the output holds, while their floats
// put the corner on the other side. Given those coordinates, the guard and the cells judge on
// them and refuse it; on the floats alone they would not.
TEST(Crossings, ExactPositionsCatchACrossingFloatRoundingHides) {
  const double a[3][3] = {{0.1, 0.1, 1.0}, {1.1, 0.2, 1.3}, {0.2, 1.1, 0.7}};
  const auto as_float = [](const double* p) {
    return std::array<double, 3>{static_cast<float>(p[0]), static_cast<float>(p[1]),
                                 static_cast<float>(p[2])};
  };
  std::array<std::array<double, 3>, 3> a_float{};
  for (int k = 0; k < 3; ++k) a_float[k] = as_float(a[k]);
  // Walk a corner across A's plane near its centroid in steps far below float's, until the doubles
  // put it below A and the floats above.
  const double normal[3] = {-0.29, 0.33, 0.97}, centroid[3] = {0.4666, 0.4666, 1.0};
  double p[3] = {};
  bool found = false;
  for (int step = -4000; step <= 4000 && !found; ++step) {
    for (int k = 0; k < 3; ++k) p[k] = centroid[k] + 1e-10 * step * normal[k];
    const auto pf = as_float(p);
    found = exact::orient3d(a[0], a[1], a[2], p) * exact::orient3d(a[0], a[1], a[2], normal) < 0 &&
            exact::orient3d(a_float[0].data(), a_float[1].data(), a_float[2].data(), pf.data()) *
                    exact::orient3d(a[0], a[1], a[2], normal) >
                0;
  }
  ASSERT_TRUE(found) << "no corner that float rounding moves across the plane";
  std::vector<double> xyz;
  for (const auto& corner : a) xyz.insert(xyz.end(), corner, corner + 3);
  // B: p and two corners well above A, so that only p's side decides.
  xyz.insert(xyz.end(), p, p + 3);
  for (const double lift : {0.3, 0.4}) {
    xyz.insert(xyz.end(), {p[0] + 0.02 * lift, p[1] + 0.01, p[2] + lift});
  }
  xyz[15] -= 0.01;
  std::vector<float> floats(xyz.begin(), xyz.end());
  const Soup soup = soup_of(floats, {{0, 1, 2}, {3, 4, 5}});
  const Triangle& first = soup.triangles[0];
  const Triangle& second = soup.triangles[1];
  ASSERT_FALSE(detail::triangles_cross(soup.grid.points(), first, second));

  const std::vector<Vec3> exact = detail::output_positions(soup.grid, xyz, false);
  const Vec3 da[3] = {exact[first[0]], exact[first[1]], exact[first[2]]};
  const Vec3 db[3] = {exact[second[0]], exact[second[1]], exact[second[2]]};
  ASSERT_TRUE(triangles_cross(da, db));
  EXPECT_TRUE(detail::output_positions(soup.grid, xyz, true).empty());

  const detail::CrossingPositions on_floats(soup.grid), on_exact(soup.grid, exact);
  EXPECT_FALSE(on_floats.cross(first, second));
  EXPECT_TRUE(on_exact.cross(first, second));
  for (const detail::CrossingPositions* positions : {&on_floats, &on_exact}) {
    detail::CrossingGuard guard(soup.grid, *positions);
    guard.file(0, soup.triangles);
    EXPECT_EQ(guard.crosses(second, std::span<const Triangle>(soup.triangles).first(1)),
              positions == &on_exact);
    EXPECT_EQ(
        detail::TriangleCells(soup.grid.points(), soup.triangles).crossing_pairs(*positions).size(),
        positions == &on_exact ? 1u : 0u);
  }
}

}  // namespace
}  // namespace g2s
