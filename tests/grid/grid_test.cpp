// Tests of the hash grid (src/grid/hash_grid.hpp, docs/algorithm.md §1): ball queries and nearest
// neighbours against brute force over awkward clouds, duplicate merging, ids, independence from
// the input order and the spacing estimate.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "grid/hash_grid.hpp"
#include "support/run_with_deadline.hpp"

namespace {

using g2s::test_support::run_with_deadline;

using g2s::HashGrid;
using g2s::Index;
using g2s::kNoIndex;
using g2s::Vec3;
using g2s::Vec3f;

struct Cloud {
  std::string name;
  std::vector<float> xyz;
  std::size_t size() const { return xyz.size() / 3; }
};

void push(Cloud& c, double x, double y, double z) {
  c.xyz.push_back(static_cast<float>(x));
  c.xyz.push_back(static_cast<float>(y));
  c.xyz.push_back(static_cast<float>(z));
}

Cloud uniform_box(std::mt19937_64& rng, int n) {
  Cloud c{"uniform box", {}};
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < n; ++i) push(c, u(rng), u(rng), 0.5 * u(rng));
  return c;
}

Cloud sphere_surface(std::mt19937_64& rng, int n) {
  Cloud c{"sphere surface", {}};
  std::normal_distribution<double> g(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    const double x = g(rng), y = g(rng), z = g(rng);
    const double r = std::sqrt(x * x + y * y + z * z);
    push(c, 3 + x / r, -2 + y / r, 1 + z / r);
  }
  return c;
}

Cloud flat_plane(std::mt19937_64& rng, int n) {
  Cloud c{"plane z=0", {}};
  std::uniform_real_distribution<double> u(0.0, 4.0);
  for (int i = 0; i < n; ++i) push(c, u(rng), u(rng), 0.0);
  return c;
}

// 80% of the points in a cube `dense` wide inside 20% scattered over a 10-wide cube: with dense =
// 1 the density ratio is 1000:1, with 0.01 it is 1e9:1.
Cloud uneven_density(std::mt19937_64& rng, int n, double dense_size = 1.0) {
  Cloud c{"uneven density", {}};
  std::uniform_real_distribution<double> dense(0.0, dense_size), sparse(-5.0, 5.0);
  for (int i = 0; i < n; ++i) {
    if (i % 5 == 0) {
      push(c, sparse(rng), sparse(rng), sparse(rng));
    } else {
      push(c, dense(rng), dense(rng), dense(rng));
    }
  }
  return c;
}

// A unit cube of points and one outlier at `far` * (1, -2, 3).
Cloud far_outlier(std::mt19937_64& rng, int n, double far) {
  Cloud c{"unit box plus one outlier", {}};
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i + 1 < n; ++i) push(c, u(rng), u(rng), u(rng));
  push(c, far, -2 * far, 3 * far);
  return c;
}

// Integer lattice: many points exactly on cell borders and at exactly the query radius.
Cloud integer_lattice() {
  Cloud c{"integer lattice 16^3", {}};
  for (int z = 0; z < 16; ++z) {
    for (int y = 0; y < 16; ++y) {
      for (int x = 0; x < 16; ++x) push(c, x, y, z);
    }
  }
  return c;
}

// Squared distance exactly as the grid computes it (float point minus double centre).
double dist2(const Vec3f& p, const Vec3& c) {
  const double dx = p.x - c.x, dy = p.y - c.y, dz = p.z - c.z;
  return dx * dx + dy * dy + dz * dz;
}

std::vector<std::uint32_t> brute_ball(const HashGrid& grid, const Vec3& c, double radius) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t i = 0; i < grid.size(); ++i) {
    if (dist2(grid.point(i), c) <= radius * radius) out.push_back(i);
  }
  return out;
}

// Checks one query: same indices as brute force, each once, with the right squared distance.
void expect_ball_matches(const HashGrid& grid, const Vec3& c, double radius,
                         const std::string& what) {
  std::vector<std::uint32_t> got;
  bool distances_ok = true;
  grid.for_each_in_ball(c, radius, [&](std::uint32_t i, double d2) {
    got.push_back(i);
    if (d2 != dist2(grid.point(i), c)) distances_ok = false;
  });
  EXPECT_TRUE(distances_ok) << what;
  const std::size_t visited = got.size();
  std::sort(got.begin(), got.end());
  EXPECT_EQ(std::unique(got.begin(), got.end()), got.end()) << what << ": a point visited twice";
  ASSERT_EQ(visited, got.size()) << what;
  const std::vector<std::uint32_t> want = brute_ball(grid, c, radius);
  ASSERT_EQ(got, want) << what << " centre (" << c.x << ", " << c.y << ", " << c.z << ") radius "
                       << radius;
  // BallQuery::visits answers the same for every point.
  const HashGrid::BallQuery query(grid, c, radius);
  std::size_t k = 0;
  for (std::uint32_t i = 0; i < grid.size(); ++i) {
    const bool in = k < got.size() && got[k] == i;
    k += in;
    ASSERT_EQ(query.visits(grid, i), in) << what << ": point " << i;
  }
}

struct Box {
  double lo[3], hi[3];
  double extent() const { return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}); }
};

Box bounds(const Cloud& c) {
  Box b{{c.xyz[0], c.xyz[1], c.xyz[2]}, {c.xyz[0], c.xyz[1], c.xyz[2]}};
  for (std::size_t i = 0; i < c.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::min<double>(b.lo[a], c.xyz[3 * i + a]);
      b.hi[a] = std::max<double>(b.hi[a], c.xyz[3 * i + a]);
    }
  }
  return b;
}

std::vector<Cloud> awkward_clouds() {
  std::mt19937_64 rng(12345);
  std::vector<Cloud> clouds;
  clouds.push_back(uniform_box(rng, 4000));
  clouds.push_back(sphere_surface(rng, 4000));
  clouds.push_back(flat_plane(rng, 4000));
  clouds.push_back(uneven_density(rng, 5000));
  clouds.push_back(far_outlier(rng, 3000, 5.0));  // ~470 spacings out
  clouds.push_back(integer_lattice());
  return clouds;
}

TEST(HashGrid, BallQueryFindsExactlyThePointsBruteForceFinds) {
  for (const Cloud& cloud : awkward_clouds()) {
    const HashGrid grid(cloud.xyz, {});
    ASSERT_EQ(grid.size(), cloud.size()) << cloud.name;  // no duplicates in these clouds
    const Box box = bounds(cloud);
    const double extent = box.extent();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int q = 0; q < 200; ++q) {
      // Centres in the bounding box grown by half its size on every side: some lie outside.
      Vec3 c;
      double* cc[3] = {&c.x, &c.y, &c.z};
      for (int a = 0; a < 3; ++a) {
        const double span = box.hi[a] - box.lo[a];
        *cc[a] = box.lo[a] - 0.5 * span + 2.0 * span * unit(rng);
      }
      // Radii from zero and a few spacings to larger than the whole cloud.
      double radius = 0;
      switch (q % 10) {
        case 0:
          radius = 0;
          break;
        case 1:
        case 2:
        case 3:
          radius = grid.spacing() * 5 * unit(rng);
          break;
        case 4:
        case 5:
          radius = extent * 0.1 * unit(rng);
          break;
        case 6:
        case 7:
          radius = extent * 0.4 * unit(rng);
          break;
        case 8:
          radius = extent * unit(rng);
          break;
        default:
          radius = extent * (2 + unit(rng));
          break;
      }
      expect_ball_matches(grid, c, radius, cloud.name);
      // Centred on a sample: radius 0 finds exactly it; radius = the distance to one of its 20
      // nearest neighbours puts that neighbour exactly on the sphere.
      const auto i = static_cast<std::uint32_t>(rng() % grid.size());
      const Vec3 pi = grid.position(i);
      std::vector<double> d2;
      for (std::uint32_t j = 0; j < grid.size(); ++j) d2.push_back(dist2(grid.point(j), pi));
      const auto k = static_cast<std::ptrdiff_t>(1 + rng() % 20);
      std::nth_element(d2.begin(), d2.begin() + k, d2.end());
      expect_ball_matches(grid, pi, 0.0, cloud.name + " (radius 0 on a sample)");
      expect_ball_matches(grid, pi, std::sqrt(d2[static_cast<std::size_t>(k)]),
                          cloud.name + " (sample on the sphere)");
      if (HasFatalFailure()) return;
    }
  }
}

TEST(HashGrid, BallOfRadiusZeroOnASampleFindsOnlyThatSample) {
  std::mt19937_64 rng(3);
  const Cloud cloud = sphere_surface(rng, 2000);
  const HashGrid grid(cloud.xyz, {});
  for (std::uint32_t i = 0; i < grid.size(); i += 37) {
    std::vector<std::uint32_t> got;
    grid.for_each_in_ball(grid.position(i), 0.0,
                          [&](std::uint32_t j, double) { got.push_back(j); });
    EXPECT_EQ(got, std::vector<std::uint32_t>{i});
  }
}

TEST(HashGrid, LatticeQueriesAtIntegerRadiiIncludePointsExactlyOnTheSphere) {
  const Cloud cloud = integer_lattice();
  const HashGrid grid(cloud.xyz, {});
  for (int r = 0; r <= 5; ++r) {
    for (std::uint32_t i = 0; i < grid.size(); i += 97) {
      expect_ball_matches(grid, grid.position(i), r, "lattice");
      if (HasFatalFailure()) return;
    }
  }
  // A ball of radius 1 at an interior lattice point holds the point and its 6 axis neighbours.
  std::size_t count = 0;
  grid.for_each_in_ball(Vec3{5, 5, 5}, 1.0, [&](std::uint32_t, double) { ++count; });
  EXPECT_EQ(count, 7u);
}

TEST(HashGrid, EmptyAndSinglePointGridsAnswerQueries) {
  const HashGrid empty(std::span<const float>{}, {});
  EXPECT_EQ(empty.size(), 0u);
  std::size_t visited = 0;
  empty.for_each_in_ball(Vec3{0, 0, 0}, 1e9, [&](std::uint32_t, double) { ++visited; });
  EXPECT_EQ(visited, 0u);

  const std::vector<float> one{1.5f, -2.0f, 7.0f};
  const std::vector<Index> id{42};
  const HashGrid single(one, id);
  ASSERT_EQ(single.size(), 1u);
  EXPECT_EQ(single.id(0), 42u);
  single.for_each_in_ball(Vec3{1.5, -2.0, 7.0}, 0.0, [&](std::uint32_t, double) { ++visited; });
  single.for_each_in_ball(Vec3{100, 100, 100}, 1.0, [&](std::uint32_t, double) { ++visited; });
  EXPECT_EQ(visited, 1u);
  EXPECT_EQ(single.nearest(0, 1e9, [](std::uint32_t) { return true; }), kNoIndex);
}

std::uint32_t brute_nearest(const HashGrid& grid, std::uint32_t i, double max_radius,
                            const std::vector<std::uint8_t>& keep) {
  std::uint32_t best = kNoIndex;
  double best_d2 = 0;
  const Vec3 c = grid.position(i);
  for (std::uint32_t j = 0; j < grid.size(); ++j) {
    if (j == i || !keep[j]) continue;
    const double d2 = dist2(grid.point(j), c);
    if (d2 > max_radius * max_radius) continue;
    if (best == kNoIndex || d2 < best_d2) best = j, best_d2 = d2;  // ties: smallest index
  }
  return best;
}

TEST(HashGrid, NearestWithKeepFilterMatchesBruteForce) {
  for (const Cloud& cloud : awkward_clouds()) {
    const HashGrid grid(cloud.xyz, {});
    std::mt19937_64 rng(11);
    // Keep a random third of the points, so the nearest kept one is often several cells away.
    std::vector<std::uint8_t> keep(grid.size());
    for (auto& k : keep) k = rng() % 3 == 0;
    const double extent = bounds(cloud).extent();
    for (int q = 0; q < 200; ++q) {
      const auto i = static_cast<std::uint32_t>(rng() % grid.size());
      const double max_radius = q % 2 ? extent * 3 : grid.spacing() * 2.5;
      const std::uint32_t got =
          grid.nearest(i, max_radius, [&](std::uint32_t j) { return keep[j] != 0; });
      const std::uint32_t want = brute_nearest(grid, i, max_radius, keep);
      ASSERT_EQ(got, want) << cloud.name << ": point " << i << " max_radius " << max_radius;
    }
  }
}

TEST(HashGrid, NearestOnLatticeBreaksTiesBySmallestIndex) {
  const Cloud cloud = integer_lattice();
  const HashGrid grid(cloud.xyz, {});
  const std::vector<std::uint8_t> all(grid.size(), 1);
  for (std::uint32_t i = 0; i < grid.size(); i += 13) {
    const std::uint32_t got = grid.nearest(i, 100.0, [](std::uint32_t) { return true; });
    ASSERT_EQ(got, brute_nearest(grid, i, 100.0, all)) << "point " << i;
    EXPECT_EQ(dist2(grid.point(got), grid.position(i)), 1.0);
  }
}

// 1000 distinct points plus 400 exact copies of some of them (some copied several times), with
// global ids that are a shuffled, sparse set.
struct DuplicateCloud {
  std::vector<float> xyz;
  std::vector<Index> ids;
  std::size_t distinct = 0;
  std::size_t copies = 0;
};

DuplicateCloud duplicate_cloud(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  DuplicateCloud d;
  d.distinct = 1000;
  d.copies = 400;
  std::vector<float> base;
  for (std::size_t i = 0; i < d.distinct; ++i) {
    for (int a = 0; a < 3; ++a) base.push_back(static_cast<float>(u(rng)));
  }
  std::vector<std::size_t> source(d.distinct);
  std::iota(source.begin(), source.end(), 0);
  for (std::size_t k = 0; k < d.copies; ++k) source.push_back(rng() % 50);  // heavy repeats
  std::shuffle(source.begin(), source.end(), rng);
  for (std::size_t s : source) {
    d.xyz.insert(d.xyz.end(), base.begin() + 3 * s, base.begin() + 3 * s + 3);
  }
  d.ids.resize(source.size());
  for (std::size_t k = 0; k < d.ids.size(); ++k) d.ids[k] = static_cast<Index>(7 * k + 1'000'000);
  std::shuffle(d.ids.begin(), d.ids.end(), rng);
  return d;
}

using Key = std::array<float, 3>;

TEST(HashGrid, ExactDuplicatesAreMergedKeepingTheSmallestId) {
  const DuplicateCloud d = duplicate_cloud(5);
  const HashGrid grid(d.xyz, d.ids);
  EXPECT_EQ(grid.duplicates_merged(), d.copies);
  ASSERT_EQ(grid.size(), d.distinct);
  std::map<Key, Index> smallest;
  for (std::size_t k = 0; k < d.ids.size(); ++k) {
    const Key key{d.xyz[3 * k], d.xyz[3 * k + 1], d.xyz[3 * k + 2]};
    auto [it, fresh] = smallest.emplace(key, d.ids[k]);
    if (!fresh) it->second = std::min(it->second, d.ids[k]);
  }
  std::map<Key, int> seen;
  for (std::uint32_t i = 0; i < grid.size(); ++i) {
    const Vec3f& p = grid.point(i);
    const Key key{p.x, p.y, p.z};
    ASSERT_TRUE(smallest.contains(key)) << "grid point not in the input";
    EXPECT_EQ(grid.id(i), smallest[key]) << "point " << i;
    EXPECT_EQ(++seen[key], 1) << "a position kept twice";
  }
}

TEST(HashGrid, EveryPointKeepsTheIdItWasGiven) {
  std::mt19937_64 rng(9);
  const Cloud cloud = sphere_surface(rng, 3000);
  std::vector<Index> ids(cloud.size());
  for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = static_cast<Index>(4'000'000'000u - 3 * k);
  const HashGrid grid(cloud.xyz, ids);
  const HashGrid implicit(cloud.xyz, {});
  ASSERT_EQ(grid.size(), cloud.size());
  std::map<Key, std::size_t> index_of;
  for (std::size_t k = 0; k < cloud.size(); ++k) {
    index_of[{cloud.xyz[3 * k], cloud.xyz[3 * k + 1], cloud.xyz[3 * k + 2]}] = k;
  }
  for (std::uint32_t i = 0; i < grid.size(); ++i) {
    const Key key{grid.point(i).x, grid.point(i).y, grid.point(i).z};
    const Key key2{implicit.point(i).x, implicit.point(i).y, implicit.point(i).z};
    EXPECT_EQ(grid.id(i), ids[index_of.at(key)]);
    EXPECT_EQ(implicit.id(i), index_of.at(key2));  // empty ids: the input index
  }
}

void expect_same_grid(const HashGrid& a, const HashGrid& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.duplicates_merged(), b.duplicates_merged());
  EXPECT_EQ(a.spacing(), b.spacing());
  EXPECT_EQ(a.cell_size(), b.cell_size());
  for (std::uint32_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.id(i), b.id(i)) << "point " << i;
    ASSERT_EQ(a.point(i).x, b.point(i).x);
    ASSERT_EQ(a.point(i).y, b.point(i).y);
    ASSERT_EQ(a.point(i).z, b.point(i).z);
  }
}

TEST(HashGrid, ShuffledInputGivesTheSamePointOrderAndIds) {
  const DuplicateCloud d = duplicate_cloud(21);
  const HashGrid reference(d.xyz, d.ids);
  std::mt19937_64 rng(1);
  for (int round = 0; round < 5; ++round) {
    std::vector<std::size_t> perm(d.ids.size());
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), rng);
    std::vector<float> xyz;
    std::vector<Index> ids;
    for (std::size_t k : perm) {
      xyz.insert(xyz.end(), d.xyz.begin() + 3 * k, d.xyz.begin() + 3 * k + 3);
      ids.push_back(d.ids[k]);
    }
    const HashGrid shuffled(xyz, ids);
    expect_same_grid(reference, shuffled);
  }
  // And a cloud without duplicates, ids implicit in the reference and explicit when shuffled.
  std::mt19937_64 rng2(2);
  const Cloud cloud = uneven_density(rng2, 4000);
  const HashGrid plain(cloud.xyz, {});
  std::vector<Index> perm(cloud.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), rng2);
  std::vector<float> xyz;
  for (Index k : perm)
    xyz.insert(xyz.end(), cloud.xyz.begin() + 3 * k, cloud.xyz.begin() + 3 * k + 3);
  expect_same_grid(plain, HashGrid(xyz, perm));
}

TEST(HashGrid, SpacingEqualsTheStepOfA2DLattice) {
  for (double h : {0.37, 1.0, 250.0, 1e-3}) {
    Cloud cloud{"lattice", {}};
    for (int j = 0; j < 100; ++j) {
      for (int i = 0; i < 100; ++i) push(cloud, 10 * h + i * h, -3 * h + j * h, 0.0);
    }
    const HashGrid grid(cloud.xyz, {});
    EXPECT_NEAR(grid.spacing(), h, 1e-5 * h) << "step " << h;
    // Cells of a few spacings, not degenerate.
    EXPECT_GT(grid.cell_size(), h);
    EXPECT_LT(grid.cell_size(), 10 * h);
  }
}

TEST(HashGrid, SpacingIsWithinTenPercentOfTheMedianNearestNeighbourDistance) {
  std::mt19937_64 rng(4);
  for (const Cloud& cloud : {sphere_surface(rng, 3000), flat_plane(rng, 3000)}) {
    const HashGrid grid(cloud.xyz, {});
    std::vector<double> nn;
    for (std::uint32_t i = 0; i < grid.size(); ++i) {
      double best = INFINITY;
      for (std::uint32_t j = 0; j < grid.size(); ++j) {
        if (j != i) best = std::min(best, dist2(grid.point(j), grid.position(i)));
      }
      nn.push_back(std::sqrt(best));
    }
    std::nth_element(nn.begin(), nn.begin() + static_cast<std::ptrdiff_t>(nn.size() / 2), nn.end());
    const double median = nn[nn.size() / 2];
    EXPECT_NEAR(grid.spacing(), median, 0.1 * median) << cloud.name;
  }
}

// A cloud of twins: every point of a plane with a copy 1/1000 of the spacing away, the copies
// listed first but with the larger ids. Given the twin distance, the grid keeps exactly the
// originals, whatever the order, measures the plane's own spacing and maps them back to their
// places; points flagged to be kept stay, and without the twin distance every point does.
TEST(HashGrid, TwinsLeaveOutTheCopyWithTheLargerId) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  Cloud plane{"jittered lattice", {}};  // no two points nearer than 0.8 steps
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 50; ++j) push(plane, i + jitter(rng), j + jitter(rng), 0.0);
  }
  const auto n = static_cast<Index>(plane.size());
  const HashGrid alone(plane.xyz, {});
  std::normal_distribution<double> g(0.0, 1e-3 * alone.spacing());
  std::vector<float> xyz;
  std::vector<Index> ids;
  for (Index k = 0; k < n; ++k) {
    const float* p = &plane.xyz[3 * k];
    xyz.insert(xyz.end(), {static_cast<float>(p[0] + g(rng)), static_cast<float>(p[1] + g(rng)),
                           static_cast<float>(g(rng))});
    ids.push_back(n + k);
    xyz.insert(xyz.end(), p, p + 3);
    ids.push_back(k);
  }
  const HashGrid grid(xyz, ids, 0.5 * alone.spacing(), 0.25 * alone.spacing());
  ASSERT_EQ(grid.size(), n);
  EXPECT_EQ(grid.twins_left_out(), n);
  EXPECT_EQ(grid.duplicates_merged(), 0u);
  EXPECT_EQ(grid.spacing(), alone.spacing());
  for (std::uint32_t i = 0; i < grid.size(); ++i) {
    ASSERT_LT(grid.id(i), n);
    const std::uint32_t s = grid.source(i);
    EXPECT_EQ(ids[s], grid.id(i));
    EXPECT_EQ(xyz[3 * s], grid.point(i).x);
    EXPECT_EQ(xyz[3 * s + 1], grid.point(i).y);
    EXPECT_EQ(xyz[3 * s + 2], grid.point(i).z);
  }
  std::vector<std::uint8_t> keep(ids.size(), 0);
  for (std::size_t s = 0; s < ids.size(); s += 10) keep[s] = 1;  // every fifth copy
  EXPECT_EQ(HashGrid(xyz, ids, 0.5 * alone.spacing(), 0.25 * alone.spacing(), keep).size(),
            n + n / 5);
  EXPECT_EQ(HashGrid(xyz, ids).size(), 2 * n);
}

// Under 4,096 points every point is sampled: the spacing is the median of all nearest-neighbour
// distances, and its lower bound the order statistic m/2 - 1.96 sqrt(m)/2 of them.
TEST(HashGrid, SpacingLowerBoundIsAnOrderStatisticBelowTheMedian) {
  std::mt19937_64 rng(5);
  for (const Cloud& cloud : {sphere_surface(rng, 3000), flat_plane(rng, 1000)}) {
    const HashGrid grid(cloud.xyz, {});
    std::vector<double> nn;  // computed as the grid computes them
    for (std::uint32_t i = 0; i < grid.size(); ++i) {
      double best = INFINITY;
      for (std::uint32_t j = 0; j < grid.size(); ++j) {
        if (j != i) best = std::min(best, norm2(grid.position(i) - grid.position(j)));
      }
      nn.push_back(std::sqrt(best));
    }
    std::sort(nn.begin(), nn.end());
    const std::size_t m = nn.size();
    const auto lower = static_cast<std::size_t>(
        std::floor(static_cast<double>(m / 2) - 0.98 * std::sqrt(static_cast<double>(m))));
    EXPECT_EQ(grid.spacing(), nn[m / 2]) << cloud.name;
    EXPECT_EQ(grid.spacing_lower_bound(), nn[lower]) << cloud.name;
    EXPECT_LT(grid.spacing_lower_bound(), grid.spacing()) << cloud.name;
  }
  // Every distance equal (a lattice): no spread, the bound is the spacing.
  Cloud lattice{"lattice", {}};
  for (int j = 0; j < 50; ++j) {
    for (int i = 0; i < 50; ++i) push(lattice, i * 0.5, j * 0.5, 0.0);
  }
  const HashGrid grid(lattice.xyz, {});
  EXPECT_EQ(grid.spacing_lower_bound(), grid.spacing());
}

// Builds the grid, then checks ball queries (radius 0, a few spacings, larger than the cloud) and
// the nearest neighbour of every 50th point against brute force. "" when all agree.
std::string check_grid_against_brute_force(const Cloud& cloud) {
  const HashGrid grid(cloud.xyz, {});
  if (grid.size() != cloud.size()) return "points lost";
  const Box box = bounds(cloud);
  const double extent = box.extent();
  std::mt19937_64 rng(3);
  for (int q = 0; q < 30; ++q) {
    const auto i = static_cast<std::uint32_t>(rng() % grid.size());
    const double radius = q % 3 == 0 ? 0.0 : q % 3 == 1 ? 4 * grid.spacing() : 2 * extent;
    std::vector<std::uint32_t> got;
    grid.for_each_in_ball(grid.position(i), radius,
                          [&](std::uint32_t j, double) { got.push_back(j); });
    std::sort(got.begin(), got.end());
    if (got != brute_ball(grid, grid.position(i), radius)) {
      return "ball query differs at point " + std::to_string(i) + " radius " +
             std::to_string(radius);
    }
  }
  const std::vector<std::uint8_t> all(grid.size(), 1);
  for (std::uint32_t i = 0; i < grid.size(); i += 50) {
    const std::uint32_t got = grid.nearest(i, 3 * extent, [](std::uint32_t) { return true; });
    if (got != brute_nearest(grid, i, 3 * extent, all)) {
      return "nearest differs at point " + std::to_string(i);
    }
  }
  return "";
}

// Regression: the spacing estimate's nearest() once searched an isolated point's neighbourhood
// cell by cell, cost (distance / cell)^3: an outlier 1e4 away took years. Now the estimate skips
// points with no neighbour within 64 cells, and a ball spanning more cells than there are points
// scans the points instead. Expected: well under a second.
TEST(HashGrid, CloudWithAFarOutlierIsBuiltAndQueriedQuickly) {
  std::mt19937_64 rng(8);
  const Cloud cloud = far_outlier(rng, 3000, 1e4);
  const std::string failure =
      run_with_deadline(3.0, [&] { return check_grid_against_brute_force(cloud); });
  EXPECT_EQ(failure, "") << "3000 points in [0,1]^3 + one at (1e4, -2e4, 3e4)";
}

TEST(HashGrid, CloudOfVeryUnevenDensityIsBuiltAndQueriedQuickly) {
  std::mt19937_64 rng(8);
  const Cloud cloud = uneven_density(rng, 5000, 0.01);
  const std::string failure =
      run_with_deadline(3.0, [&] { return check_grid_against_brute_force(cloud); });
  EXPECT_EQ(failure, "") << "4000 points in [0,0.01]^3 + 1000 in [-5,5]^3";
}

}  // namespace
