// The triangulation of a hole's loop (src/grow/hole_filling.hpp) on loops whose answers are
// known: a planar convex loop gives n - 2 triangles covering exactly its area, all facing one
// way; on bent loops its sharpest fold is the gentlest of all triangulations', as an
// exhaustive search finds it, with or without triangles refused; forbidden chords are never used; a
// loop that can only be closed with forbidden chords, or only with degenerate triangles, is left
// open.
#include "grow/hole_filling.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

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

// The mesh around a flat loop in the plane z = 0, facing +z.
std::vector<Vec3> flat_around(std::size_t n) {
  return std::vector<Vec3>(n, Vec3{0, 0, 1});
}

const auto any_triangle = [](std::size_t, std::size_t, std::size_t) { return true; };

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
        points, loop, flat_around(loop.size()), [](std::size_t, std::size_t) { return true; },
        any_triangle, scratch, out));
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
  ASSERT_TRUE(detail::triangulate_loop(points, loop, flat_around(8), from_zero, any_triangle,
                                       scratch, out));
  for (const Triangle& t : out) {
    EXPECT_EQ(t[0], 0u) << "every triangle of the fan has corner 0 first";
  }
}

TEST(HoleFilling, ForbiddenTrianglesAreAvoidedOrTheLoopStaysOpen) {
  const std::vector<Vec3f> points = regular_polygon(4);
  const std::vector<Index> loop = identity_loop(4);
  const auto all_chords = [](std::size_t, std::size_t) { return true; };
  detail::HoleScratch scratch;
  std::vector<Triangle> out;
  // Without triangle 0-1-2 the square can only be split along 1-3.
  const auto not_012 = [](std::size_t i, std::size_t k, std::size_t j) {
    return !(i == 0 && k == 1 && j == 2);
  };
  ASSERT_TRUE(
      detail::triangulate_loop(points, loop, flat_around(4), all_chords, not_012, scratch, out));
  ASSERT_EQ(out.size(), 2u);
  for (const Triangle& t : out) {
    EXPECT_TRUE(std::find(t.begin(), t.end(), 1u) != t.end() &&
                std::find(t.begin(), t.end(), 3u) != t.end());
  }
  // Without 0-1-2 and 0-1-3 no split is left.
  out.clear();
  const auto neither = [](std::size_t i, std::size_t k, std::size_t) {
    return !(i == 0 && k == 1);
  };
  EXPECT_FALSE(
      detail::triangulate_loop(points, loop, flat_around(4), all_chords, neither, scratch, out));
  EXPECT_TRUE(out.empty());
}

TEST(HoleFilling, LoopThatNeedsAForbiddenChordStaysOpen) {
  const std::vector<Vec3f> points = regular_polygon(4);
  const std::vector<Index> loop = identity_loop(4);
  detail::HoleScratch scratch;
  std::vector<Triangle> out;
  EXPECT_FALSE(detail::triangulate_loop(
      points, loop, flat_around(4), [](std::size_t, std::size_t) { return false; }, any_triangle,
      scratch, out));
  EXPECT_TRUE(out.empty());
}

TEST(HoleFilling, CollinearLoopStaysOpen) {
  const std::vector<Vec3f> points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  const std::vector<Index> loop = identity_loop(4);
  detail::HoleScratch scratch;
  std::vector<Triangle> out;
  EXPECT_FALSE(detail::triangulate_loop(
      points, loop, flat_around(4), [](std::size_t, std::size_t) { return true; }, any_triangle,
      scratch, out));
}

TEST(HoleFilling, LoopWithAnEdgeNoTriangleMayUseIsGivenUpEarly) {
  // Every triangle on the loop edge 5-6 is forbidden: no triangulation exists, and that is
  // found by asking about the triangles on that edge (and a few ears), not about all of them.
  constexpr int n = 24;
  const std::vector<Vec3f> points = regular_polygon(n);
  const std::vector<Index> loop = identity_loop(n);
  std::size_t asked = 0;
  const auto not_on_5_6 = [&](std::size_t i, std::size_t k, std::size_t j) {
    ++asked;
    return !((i == 5 && k == 6) || (k == 5 && j == 6));
  };
  detail::HoleScratch scratch;
  std::vector<Triangle> out;
  EXPECT_FALSE(detail::triangulate_loop(
      points, loop, flat_around(loop.size()), [](std::size_t, std::size_t) { return true; },
      not_on_5_6, scratch, out));
  EXPECT_TRUE(out.empty());
  EXPECT_LE(asked, static_cast<std::size_t>(2 * n));
  // Each triangle is asked about once, however often the programme needs it.
  asked = 0;
  std::size_t distinct = 0;
  std::vector<std::uint8_t> seen(n * n * n, 0);
  const auto counting = [&](std::size_t i, std::size_t k, std::size_t j) {
    ++asked;
    distinct += !seen[(i * n + k) * n + j]++;
    return true;
  };
  ASSERT_TRUE(detail::triangulate_loop(
      points, loop, flat_around(loop.size()), [](std::size_t, std::size_t) { return true; },
      counting, scratch, out));
  EXPECT_EQ(asked, distinct);
}

// Every triangulation of loop positions [i, j] closed by chord i-j, as lists of triangles.
void all_triangulations(std::size_t i, std::size_t j, std::vector<std::vector<Triangle>>& out) {
  out.clear();
  if (j - i < 2) {
    out.push_back({});
    return;
  }
  for (std::size_t k = i + 1; k < j; ++k) {
    std::vector<std::vector<Triangle>> left, right;
    all_triangulations(i, k, left);
    all_triangulations(k, j, right);
    for (const auto& l : left) {
      for (const auto& r : right) {
        std::vector<Triangle> t = l;
        t.insert(t.end(), r.begin(), r.end());
        t.push_back({static_cast<Index>(i), static_cast<Index>(k), static_cast<Index>(j)});
        out.push_back(std::move(t));
      }
    }
  }
}

// Bent loops against an exhaustive search over every triangulation, with every triangle allowed
// or (refuse) about one in four refused by triangle_ok: the filling's sharpest fold is the
// gentlest of the allowed triangulations', it uses no refused triangle, and the loop stays open
// exactly when no triangulation avoids them.
void check_against_exhaustive_search(bool refuse) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> jitter(-0.4f, 0.4f);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 4 + trial % 4;
    // A loop around the z axis, its corners pushed up and down, and tilted mesh around it.
    std::vector<Vec3f> points = regular_polygon(n);
    for (Vec3f& p : points) p.z = 2 * jitter(rng);
    std::vector<Vec3> around;
    for (int k = 0; k < n; ++k) around.push_back(normalized(Vec3{jitter(rng), jitter(rng), 1}));
    const std::vector<Index> loop = identity_loop(n);
    const auto normal = [&](const Triangle& t) {
      const Vec3 a(points[t[0]]);
      return normalized(cross(Vec3(points[t[1]]) - a, Vec3(points[t[2]]) - a));
    };
    // The sharpest fold of a triangulation: across every edge two triangles (or one and the
    // mesh around) share.
    const auto judge = [&](const std::vector<Triangle>& fill, double& area) {
      double fold_cos = 1;
      area = 0;
      for (const Triangle& t : fill) {
        area += detail::triangle_area(points[t[0]], points[t[1]], points[t[2]]);
        for (int e = 0; e < 3; ++e) {
          const Index u = t[e], v = t[(e + 1) % 3];
          const auto un = static_cast<Index>(n);
          if ((u + 1) % un == v) fold_cos = std::min(fold_cos, dot(normal(t), around[u]));
          for (const Triangle& o : fill) {
            for (int f = 0; f < 3; ++f) {
              if (o[f] == v && o[(f + 1) % 3] == u) {
                fold_cos = std::min(fold_cos, dot(normal(t), normal(o)));
              }
            }
          }
        }
      }
      return fold_cos;
    };
    std::vector<std::uint8_t> refused(static_cast<std::size_t>(n * n * n), 0);
    for (std::uint8_t& r : refused) r = refuse && rng() % 4 == 0;
    const auto is_refused = [&](const Triangle& t) {  // corners i < k < j
      return refused[(t[0] * static_cast<std::size_t>(n) + t[1]) * static_cast<std::size_t>(n) +
                     t[2]] != 0;
    };
    std::vector<std::vector<Triangle>> every;
    all_triangulations(0, static_cast<std::size_t>(n - 1), every);
    std::erase_if(every, [&](const std::vector<Triangle>& fill) {
      return std::any_of(fill.begin(), fill.end(), is_refused);
    });
    double best_cos = -2;
    for (const auto& fill : every) {
      double area = 0;
      best_cos = std::max(best_cos, judge(fill, area));
    }
    double worst_area_at_best = 0;  // the area is chosen greedily: within those of the best
    for (const auto& fill : every) {
      double area = 0;
      if (judge(fill, area) >= best_cos - 1e-12) {
        worst_area_at_best = std::max(worst_area_at_best, area + 1e-9);
      }
    }
    detail::HoleScratch scratch;
    std::vector<Triangle> out;
    std::size_t asked = 0;
    const auto allowed = [&](std::size_t i, std::size_t k, std::size_t j) {
      ++asked;
      return !is_refused({static_cast<Index>(i), static_cast<Index>(k), static_cast<Index>(j)});
    };
    const auto fold_cos = detail::triangulate_loop(
        points, loop, around, [](std::size_t, std::size_t) { return true; }, allowed, scratch, out);
    EXPECT_LE(asked, static_cast<std::size_t>(n * (n - 1) * (n - 2) / 6)) << "trial " << trial;
    ASSERT_EQ(fold_cos.has_value(), !every.empty()) << "trial " << trial;
    if (!fold_cos) continue;
    for (Triangle t : out) {
      std::sort(t.begin(), t.end());
      EXPECT_FALSE(is_refused(t)) << "trial " << trial;
    }
    double area = 0;
    EXPECT_NEAR(judge(out, area), best_cos, 1e-9) << "trial " << trial;
    EXPECT_NEAR(*fold_cos, best_cos, 1e-9) << "trial " << trial;
    EXPECT_LE(area, worst_area_at_best) << "trial " << trial;
  }
}

TEST(HoleFilling, BentLoopsGetTheGentlestFillingAsAnExhaustiveSearchFindsIt) {
  check_against_exhaustive_search(/*refuse=*/false);
}

TEST(HoleFilling, RefusedTrianglesLeaveTheGentlestAllowedFilling) {
  check_against_exhaustive_search(/*refuse=*/true);
}

}  // namespace
}  // namespace g2s
