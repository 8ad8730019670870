// Tests of the synthetic clouds (include/g2s/synth.hpp): exact counts, points on the analytic
// surfaces, even scanner-like spacing (no clumps), noise and outlier statistics, determinism,
// chunk independence, streaming == in-memory, and the `g2s synth` command line.
#include "g2s/synth.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <string>
#include <unordered_map>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"
#include "synth/sampler.hpp"

namespace {

using g2s::PointCloud;
using g2s::SynthOptions;
using g2s::SynthShape;

constexpr SynthShape kAllShapes[] = {SynthShape::sphere, SynthShape::torus,  SynthShape::cube,
                                     SynthShape::plate,  SynthShape::uneven, SynthShape::terrain};

SynthOptions options_for(SynthShape shape, std::uint64_t points, std::uint64_t seed = 1) {
  SynthOptions options;
  options.shape = shape;
  options.points = points;
  options.seed = seed;
  return options;
}

struct Vec {
  double x, y, z;
};

Vec point(const PointCloud& cloud, std::size_t i) {
  return {cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]};
}

// Distance from p to the box surface [-a,a] x [-b,b] x [-c,c] (inside or outside).
double box_distance(const Vec& p, double a, double b, double c) {
  const double dx = std::abs(p.x) - a, dy = std::abs(p.y) - b, dz = std::abs(p.z) - c;
  const double outside = std::hypot(std::max(dx, 0.0), std::max(dy, 0.0), std::max(dz, 0.0));
  const double inside = std::min(0.0, std::max({dx, dy, dz}));
  return outside + std::abs(inside);
}

// Distance from p to the shape's surface (terrain: vertical distance, an upper bound).
double surface_distance(SynthShape shape, const Vec& p) {
  switch (shape) {
    case SynthShape::sphere:
    case SynthShape::uneven:
      return std::abs(std::hypot(p.x, p.y, p.z) - 1.0);
    case SynthShape::torus:
      return std::abs(std::hypot(std::hypot(p.x, p.y) - 1.0, p.z) - 0.35);
    case SynthShape::cube:
      return box_distance(p, 1.0, 1.0, 1.0);
    case SynthShape::plate:
      return box_distance(p, 1.0, 1.0, 0.025);
    case SynthShape::terrain: {
      const bool in_domain = p.x >= 0.0 && p.x <= 1.0 && p.y >= 0.0 && p.y <= 1.0;
      return in_domain ? std::abs(p.z - g2s::synth::terrain_height(p.x, p.y))
                       : std::numeric_limits<double>::infinity();
    }
  }
  return std::numeric_limits<double>::infinity();
}

// Nearest-neighbour distance of every point, through a uniform grid of the given cell size
// (every point must have a neighbour closer than `cell`).
std::vector<double> nearest_distances(const PointCloud& cloud, double cell) {
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return (i * 73856093) ^ (j * 19349663) ^ (k * 83492791);
  };
  auto coord = [&](double v) { return static_cast<std::int64_t>(std::floor(v / cell)); };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec p = point(cloud, i);
    grid[key(coord(p.x), coord(p.y), coord(p.z))].push_back(i);
  }
  std::vector<double> result(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec p = point(cloud, i);
    double best = std::numeric_limits<double>::infinity();
    for (std::int64_t di = -1; di <= 1; ++di)
      for (std::int64_t dj = -1; dj <= 1; ++dj)
        for (std::int64_t dk = -1; dk <= 1; ++dk) {
          const auto it = grid.find(key(coord(p.x) + di, coord(p.y) + dj, coord(p.z) + dk));
          if (it == grid.end()) continue;
          for (const std::size_t j : it->second) {
            if (j == i) continue;
            const Vec q = point(cloud, j);
            best = std::min(best, std::hypot(p.x - q.x, p.y - q.y, p.z - q.z));
          }
        }
    result[i] = best;
  }
  return result;
}

double mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (const double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

TEST(Synth, ShapeNamesRoundTrip) {
  for (const SynthShape shape : kAllShapes) {
    const auto name = g2s::synth_shape_name(shape);
    EXPECT_EQ(g2s::synth_shape_from_name(name), shape) << name;
  }
  EXPECT_EQ(g2s::synth_shape_from_name("torus"), SynthShape::torus);
  EXPECT_FALSE(g2s::synth_shape_from_name("donut").has_value());
  EXPECT_FALSE(g2s::synth_shape_from_name("").has_value());
}

TEST(Synth, SpacingIsSqrtAreaOverPoints) {
  constexpr double pi = std::numbers::pi;
  EXPECT_DOUBLE_EQ(g2s::synth_spacing(options_for(SynthShape::sphere, 100)),
                   std::sqrt(4 * pi / 100));
  EXPECT_DOUBLE_EQ(g2s::synth_spacing(options_for(SynthShape::uneven, 100)),
                   std::sqrt(4 * pi / 100));
  EXPECT_DOUBLE_EQ(g2s::synth_spacing(options_for(SynthShape::torus, 100)),
                   std::sqrt(4 * pi * pi * 0.35 / 100));
  EXPECT_DOUBLE_EQ(g2s::synth_spacing(options_for(SynthShape::cube, 600)), 0.2);
  EXPECT_DOUBLE_EQ(g2s::synth_spacing(options_for(SynthShape::plate, 100)), std::sqrt(8.4 / 100));
  // Terrain: a height field over the unit square, a little more than 1 in area.
  const double terrain = g2s::synth_spacing(options_for(SynthShape::terrain, 1));
  EXPECT_NEAR(terrain * terrain, 1.03645, 1e-5);
}

TEST(Synth, ExactPointCounts) {
  for (const SynthShape shape : kAllShapes) {
    for (const std::uint64_t n : {1, 2, 3, 5, 7, 11, 100, 1001, 4097, 12345}) {
      const PointCloud cloud = g2s::make_synthetic_cloud(options_for(shape, n));
      EXPECT_EQ(cloud.size(), n) << g2s::synth_shape_name(shape) << " " << n;
    }
  }
}

TEST(Synth, PointsLieOnTheSurface) {
  for (const SynthShape shape : kAllShapes) {
    for (const std::uint64_t n : {7, 20000}) {
      const PointCloud cloud = g2s::make_synthetic_cloud(options_for(shape, n));
      double worst = 0.0;
      for (std::size_t i = 0; i < cloud.size(); ++i)
        worst = std::max(worst, surface_distance(shape, point(cloud, i)));
      EXPECT_LT(worst, 1e-5) << g2s::synth_shape_name(shape) << " " << n;
    }
  }
}

TEST(Synth, PointsAreRoundedToFloat) {
  const PointCloud cloud = g2s::make_synthetic_cloud(options_for(SynthShape::torus, 1000));
  for (const double v : cloud.xyz) ASSERT_EQ(v, static_cast<double>(static_cast<float>(v)));
}

TEST(Synth, BoxFacesGetPointsInProportionToArea) {
  // Cube: 6 equal faces; 6001 points -> 1000 or 1001 per face.
  const PointCloud cube = g2s::make_synthetic_cloud(options_for(SynthShape::cube, 6001));
  std::vector<int> faces(6, 0);
  for (std::size_t i = 0; i < cube.size(); ++i) {
    const Vec p = point(cube, i);
    const double c[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a)
      if (std::abs(c[a]) == 1.0) ++faces[2 * a + (c[a] < 0 ? 1 : 0)];
  }
  for (const int count : faces) {
    EXPECT_GE(count, 1000);
    EXPECT_LE(count, 1001);
  }
  // Plate: the four thin sides hold 0.4 / 8.4 of the area.
  const PointCloud plate = g2s::make_synthetic_cloud(options_for(SynthShape::plate, 84000));
  int sides = 0;
  for (std::size_t i = 0; i < plate.size(); ++i) {
    const Vec p = point(plate, i);
    if (std::abs(p.x) == 1.0 || std::abs(p.y) == 1.0) ++sides;
  }
  EXPECT_NEAR(sides, 4000, 4);
}

TEST(Synth, Deterministic) {
  for (const SynthShape shape : kAllShapes) {
    SynthOptions options = options_for(shape, 5000, 42);
    options.noise = 0.2;
    options.outliers = 0.05;
    const PointCloud a = g2s::make_synthetic_cloud(options);
    const PointCloud b = g2s::make_synthetic_cloud(options);
    EXPECT_EQ(a.xyz, b.xyz) << g2s::synth_shape_name(shape);
    options.seed = 43;
    const PointCloud c = g2s::make_synthetic_cloud(options);
    ASSERT_EQ(a.size(), c.size());
    std::size_t same = 0;
    for (std::size_t i = 0; i < a.xyz.size(); ++i) same += a.xyz[i] == c.xyz[i] ? 1 : 0;
    EXPECT_LT(same, a.xyz.size() / 10) << g2s::synth_shape_name(shape);
  }
  // Without noise, a different seed still moves every point (the jitter).
  const PointCloud a = g2s::make_synthetic_cloud(options_for(SynthShape::sphere, 1000, 1));
  const PointCloud b = g2s::make_synthetic_cloud(options_for(SynthShape::sphere, 1000, 2));
  EXPECT_NE(a.xyz, b.xyz);
}

TEST(Synth, AnyChunkingGivesTheSamePoints) {
  for (const SynthShape shape : kAllShapes) {
    SynthOptions options = options_for(shape, 3000, 7);
    options.noise = 0.1;
    options.outliers = 0.1;
    const g2s::synth::ShapeSampler sampler(options);
    const std::uint64_t total = sampler.total_points();
    ASSERT_EQ(total, 3300u);
    std::vector<float> whole(3 * total), pieces(3 * total);
    sampler.generate(0, total, whole.data());
    // Uneven pieces, crossing patch, row and surface/outlier boundaries.
    std::uint64_t begin = 0, step = 1;
    while (begin < total) {
      const std::uint64_t end = std::min(total, begin + step);
      sampler.generate(begin, end, pieces.data() + 3 * begin);
      begin = end;
      step = step * 3 % 97 + 1;
    }
    EXPECT_EQ(whole, pieces) << g2s::synth_shape_name(shape);
    const PointCloud cloud = g2s::make_synthetic_cloud(options);
    for (std::size_t k = 0; k < whole.size(); ++k)
      ASSERT_EQ(cloud.xyz[k], static_cast<double>(whole[k])) << k;
  }
}

// The spacing a good scanner gives: no clumps or near-duplicates (min nearest-neighbour distance
// well above 0) and a mean nearest-neighbour distance close to sqrt(area / points).
TEST(Synth, EvenSpacingLikeAScan) {
  for (const SynthShape shape : {SynthShape::sphere, SynthShape::torus, SynthShape::cube,
                                 SynthShape::plate, SynthShape::terrain}) {
    const SynthOptions options = options_for(shape, 20000);
    const double spacing = g2s::synth_spacing(options);
    const PointCloud cloud = g2s::make_synthetic_cloud(options);
    const std::vector<double> nn = nearest_distances(cloud, 2.0 * spacing);
    const double smallest = *std::min_element(nn.begin(), nn.end());
    const double largest = *std::max_element(nn.begin(), nn.end());
    EXPECT_GT(smallest, 0.2 * spacing) << g2s::synth_shape_name(shape);
    EXPECT_LT(largest, 2.0 * spacing) << g2s::synth_shape_name(shape);
    EXPECT_NEAR(mean(nn) / spacing, 1.0, 0.25) << g2s::synth_shape_name(shape);
  }
}

TEST(Synth, UnevenSphereDensityVaries16To1) {
  const SynthOptions options = options_for(SynthShape::uneven, 40000);
  const PointCloud cloud = g2s::make_synthetic_cloud(options);
  // Density exp(k z) with exp(2k) = 16: the caps z > 0.8 and z < -0.8 (equal areas) hold
  // masses in the ratio exp(1.8 k) = 4^1.8.
  std::size_t north = 0, south = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double z = point(cloud, i).z;
    north += z > 0.8 ? 1 : 0;
    south += z < -0.8 ? 1 : 0;
  }
  EXPECT_NEAR(static_cast<double>(north) / static_cast<double>(south), std::pow(4.0, 1.8),
              0.05 * std::pow(4.0, 1.8));
  // Spacing follows: 1:4 between the poles, and still even locally (no clumps).
  const std::vector<double> nn = nearest_distances(cloud, 4.0 * g2s::synth_spacing(options));
  std::vector<double> dense, sparse;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double z = point(cloud, i).z;
    if (z > 0.95) dense.push_back(nn[i]);
    if (z < -0.95) sparse.push_back(nn[i]);
  }
  ASSERT_FALSE(dense.empty());
  ASSERT_FALSE(sparse.empty());
  EXPECT_NEAR(mean(sparse) / mean(dense), 4.0 * std::pow(4.0, -0.05), 0.5);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double local =
        1.0 / std::sqrt(40000.0 * std::log(4.0) * std::pow(4.0, point(cloud, i).z) /
                        (2.0 * std::numbers::pi * (4.0 - 0.25)));
    ASSERT_GT(nn[i], 0.2 * local) << i;
  }
}

TEST(Synth, NoiseHasTheRequestedSigma) {
  SynthOptions options = options_for(SynthShape::sphere, 20000);
  options.noise = 0.5;
  const double sigma = options.noise * g2s::synth_spacing(options);
  const PointCloud cloud = g2s::make_synthetic_cloud(options);
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec p = point(cloud, i);
    const double d = std::hypot(p.x, p.y, p.z) - 1.0;  // signed distance to the sphere
    sum += d;
    sum2 += d * d;
  }
  const double n = static_cast<double>(cloud.size());
  const double measured = std::sqrt(sum2 / n - (sum / n) * (sum / n));
  EXPECT_NEAR(measured / sigma, 1.0, 0.2);
  EXPECT_NEAR(sum / n, 0.0, 0.1 * sigma);
}

TEST(Synth, OutliersAreAppendedInTheBoundingBox) {
  for (const SynthShape shape : kAllShapes) {
    SynthOptions options = options_for(shape, 10001);
    options.outliers = 0.25;
    const PointCloud cloud = g2s::make_synthetic_cloud(options);
    ASSERT_EQ(cloud.size(), 10001u + 2500u) << g2s::synth_shape_name(shape);
    const g2s::synth::Bounds box = g2s::synth::shape_bounds(shape);
    std::size_t off_surface = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Vec p = point(cloud, i);
      const double c[3] = {p.x, p.y, p.z};
      for (int a = 0; a < 3; ++a) {
        ASSERT_GE(c[a], static_cast<float>(box.lo[a]));
        ASSERT_LE(c[a], static_cast<float>(box.hi[a]));
      }
      const double d = surface_distance(shape, p);
      if (i < 10001) {
        ASSERT_LT(d, 1e-5) << i;
      } else {
        off_surface += d > 1e-4 ? 1 : 0;
      }
    }
    EXPECT_GT(off_surface, 2400u) << g2s::synth_shape_name(shape);
  }
  SynthOptions options = options_for(SynthShape::sphere, 3);
  options.outliers = 0.5;  // round(1.5) = 2
  EXPECT_EQ(g2s::make_synthetic_cloud(options).size(), 5u);
}

TEST(Synth, RejectsBadOptions) {
  auto code = [](const SynthOptions& options) {
    try {
      g2s::make_synthetic_cloud(options);
    } catch (const g2s::Error& e) {
      return e.code();
    }
    return g2s::Exit::ok;
  };
  SynthOptions options = options_for(SynthShape::sphere, 0);
  EXPECT_EQ(code(options), g2s::Exit::usage);
  options.points = 10;
  options.noise = -0.1;
  EXPECT_EQ(code(options), g2s::Exit::usage);
  options.noise = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(code(options), g2s::Exit::usage);
  options.noise = 0.0;
  options.outliers = -1.0;
  EXPECT_EQ(code(options), g2s::Exit::usage);
  options.outliers = std::numeric_limits<double>::infinity();
  EXPECT_EQ(code(options), g2s::Exit::usage);
  options.outliers = 0.0;
  EXPECT_EQ(code(options), g2s::Exit::ok);
}

using SynthFiles = g2s::test_support::CliTest;

// Streaming in 1M-point chunks writes exactly the in-memory cloud: more than one chunk, with a
// chunk boundary among the outliers as well.
TEST_F(SynthFiles, StreamedFileEqualsInMemoryCloud) {
  SynthOptions options = options_for(SynthShape::torus, (1u << 20) + 4321, 9);
  options.noise = 0.1;
  options.outliers = 1.0;
  const auto path = dir_ / "torus.ply";
  g2s::write_synthetic_cloud(path, options);
  g2s::ReadReport report;
  const PointCloud read = g2s::read_points(path, &report);
  EXPECT_EQ(report.format, "ply-binary-le");
  const PointCloud made = g2s::make_synthetic_cloud(options);
  ASSERT_EQ(read.size(), 2 * options.points);
  EXPECT_TRUE(read.xyz == made.xyz);
}

TEST_F(SynthFiles, CommandLine) {
  const auto path = dir_ / "cube.ply";
  const std::string output = run({"synth", "cube", "--points", "2k", "--noise", "0.1", "--outliers",
                                  "0.01", "--seed", "5", "-o", path.string()},
                                 0);
  EXPECT_NE(output.find("2000 points"), std::string::npos) << output;
  EXPECT_NE(output.find(path.filename().string()), std::string::npos) << output;
  SynthOptions options = options_for(SynthShape::cube, 2000, 5);
  options.noise = 0.1;
  options.outliers = 0.01;
  EXPECT_EQ(g2s::read_points(path).xyz, g2s::make_synthetic_cloud(options).xyz);

  run({"synth", "sphere", "-n", "1.5k", "-o", path.string()}, 0);
  EXPECT_EQ(g2s::read_points(path).size(), 1500u);

  const std::string bad = (dir_ / "bad.ply").string();
  run({"synth", "donut", "--points", "100", "-o", bad}, 2);
  for (const char* points : {"0", "1.5x", "0.5k5", "1.0001k"}) {
    run({"synth", "sphere", "--points", points, "-o", bad}, 2);
  }
  run({"synth", "sphere", "--points", "100", "--noise", "-1", "-o", bad}, 2);
  run({"synth", "sphere", "--points", "100", "--outliers", "-0.5", "-o", bad}, 2);
  run({"synth", "sphere", "--points", "100"}, 2);  // no -o
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.ply"));
  run({"synth", "sphere", "--points", "100", "-o", (dir_ / "missing" / "x.ply").string()}, 4);
}

}  // namespace
