// Tests of the tile store's spacing sample (src/tiling/tile_spacing.hpp): the three nearest
// neighbour distances it records are exactly those a search over every point gives, on clouds
// whose points sit on cell faces, crowd into a few cells, lie on a line or far apart.
#include "tiling/tile_spacing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

namespace g2s {
namespace {

// The three nearest distinct-position distances of point i, over every point.
NearestThree brute_force(const std::vector<double>& xyz, std::size_t i) {
  NearestThree squared;
  for (std::size_t j = 0; j < xyz.size() / 3; ++j) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a)
      d2 += (xyz[3 * i + a] - xyz[3 * j + a]) * (xyz[3 * i + a] - xyz[3 * j + a]);
    if (d2 > 0) squared.offer(d2);
  }
  NearestThree out;
  for (int k = 0; k < 3; ++k) out.d[k] = std::sqrt(squared.d[k]);
  return out;
}

// The cloud sample of one tile holding the whole cloud (every point sampled, no seam), with
// each sampled point's distances as the brute force gives them, where they are finite.
void expect_exact(const std::vector<double>& xyz) {
  const std::size_t n = xyz.size() / 3;
  std::vector<Index> ids(n);
  std::iota(ids.begin(), ids.end(), Index{0});
  TileBox box;
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = std::numeric_limits<double>::infinity();
    box.hi[a] = -box.lo[a];
    for (std::size_t i = 0; i < n; ++i) {
      box.lo[a] = std::min(box.lo[a], xyz[3 * i + a]);
      box.hi[a] = std::max(box.hi[a], xyz[3 * i + a]);
    }
  }
  const tiling::TileSpacing spacing = tiling::measure_tile_spacing(xyz, ids, box, box, n);
  std::vector<NearestThree> expected;
  for (std::size_t i = 0; i < n; ++i) {
    const NearestThree near = brute_force(xyz, i);
    if (std::isfinite(near.d[0])) expected.push_back(near);
  }
  // Points with no neighbour within 16 cells are left out; none of these clouds has one.
  ASSERT_EQ(spacing.cloud_sample.size(), expected.size());
  for (std::size_t s = 0; s < expected.size(); ++s) {
    for (int k = 0; k < 3; ++k) {
      if (std::isfinite(expected[s].d[k])) {
        EXPECT_EQ(spacing.cloud_sample[s].d[k], expected[s].d[k]) << "sample " << s << " k " << k;
      }
    }
  }
}

TEST(TileSpacing, NeighbourDistancesAreExact) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  {  // a noisy plane
    std::vector<double> xyz;
    for (int i = 0; i < 3000; ++i) xyz.insert(xyz.end(), {unit(rng), unit(rng), 0.01 * unit(rng)});
    expect_exact(xyz);
  }
  {  // a lattice: many points on cell faces and equal distances
    std::vector<double> xyz;
    for (int x = 0; x < 40; ++x) {
      for (int y = 0; y < 40; ++y) xyz.insert(xyz.end(), {0.125 * x, 0.125 * y, 0.0});
    }
    expect_exact(xyz);
  }
  {  // tight clusters far apart, duplicates among them
    std::vector<double> xyz;
    for (int c = 0; c < 20; ++c) {
      const double cx = 100 * unit(rng), cy = 100 * unit(rng), cz = 100 * unit(rng);
      for (int i = 0; i < 50; ++i) {
        xyz.insert(xyz.end(), {cx + 1e-3 * unit(rng), cy + 1e-3 * unit(rng), cz});
      }
      xyz.insert(xyz.end(), {cx, cy, cz});
      xyz.insert(xyz.end(), {cx, cy, cz});
    }
    expect_exact(xyz);
  }
  // Small clouds have few buckets, so cells of one search often share one.
  for (int seed = 0; seed < 20; ++seed) {
    std::vector<double> xyz;
    for (int i = 0; i < 300; ++i) xyz.insert(xyz.end(), {unit(rng), unit(rng), 0.05 * unit(rng)});
    expect_exact(xyz);
  }
  {  // a dense patch among sparse points, whose neighbours lie a few cells away
    std::vector<double> xyz;
    for (int i = 0; i < 2000; ++i) xyz.insert(xyz.end(), {0.1 * unit(rng), 0.1 * unit(rng), 0.0});
    for (int i = 0; i < 300; ++i) xyz.insert(xyz.end(), {unit(rng), unit(rng), 0.02 * unit(rng)});
    expect_exact(xyz);
  }
  {  // points on a line, at uneven steps
    std::vector<double> xyz;
    double t = 0;
    for (int i = 0; i < 2000; ++i) {
      t += 0.01 + 0.02 * unit(rng);
      xyz.insert(xyz.end(), {t, 2 * t, -t});
    }
    expect_exact(xyz);
  }
}

}  // namespace
}  // namespace g2s
