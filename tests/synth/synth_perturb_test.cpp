// Tests of noise and outliers on a measured cloud (include/g2s/synth.hpp: mean_spacing,
// perturb_cloud, `g2s synth --from`), the inputs of the paper's Tables 3 and 4: the spacing is
// the exact mean nearest-neighbour distance, sigma is measured back on a plane, the outlier count
// is exact and the outliers fill the bounding box, and the result depends only on the seed.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/synth.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

using g2s::PerturbOptions;
using g2s::PointCloud;

// A square grid of side x side points in the plane z = 0, `pitch` apart, far from the origin
// (as georeferenced scans are) so that a frame bug would show.
PointCloud plane_grid(int side, double pitch) {
  PointCloud cloud;
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      cloud.xyz.insert(cloud.xyz.end(), {5e5 + i * pitch, 4e6 + j * pitch, 100.0});
    }
  }
  return cloud;
}

int expect_error(const PointCloud& cloud, const PerturbOptions& options) {
  try {
    g2s::perturb_cloud(cloud, options);
  } catch (const g2s::Error& e) {
    return static_cast<int>(e.code());
  }
  return 0;
}

TEST(SynthPerturb, MeanSpacingOfAGridIsItsPitch) {
  EXPECT_NEAR(g2s::mean_spacing(plane_grid(50, 0.25)), 0.25, 1e-6);
  // Two points: each one's nearest is the other.
  const PointCloud pair{{0, 0, 0, 3, 4, 0}};
  EXPECT_DOUBLE_EQ(g2s::mean_spacing(pair), 5.0);
  // Uneven: 0-1-3 on a line gives distances 1, 1, 2.
  const PointCloud line{{0, 0, 0, 1, 0, 0, 3, 0, 0}};
  EXPECT_DOUBLE_EQ(g2s::mean_spacing(line), 4.0 / 3.0);
}

// The paper's noise: sigma in units of the spacing, on every coordinate. On a plane, the
// displacement along its normal (z) is the noise itself; 40,000 draws put the sample standard
// deviation within 1% of sigma (its standard error is sigma / sqrt(2n) = 0.35%).
TEST(SynthPerturb, NoiseSigmaIsMeasuredBackOnAPlane) {
  const double pitch = 0.01;
  const PointCloud plane = plane_grid(200, pitch);
  PerturbOptions options;
  options.noise = 0.3;
  options.seed = 7;
  g2s::PerturbReport report;
  const PointCloud noisy = g2s::perturb_cloud(plane, options, &report);
  ASSERT_EQ(noisy.size(), plane.size());
  EXPECT_NEAR(report.spacing, pitch, 1e-6);
  EXPECT_DOUBLE_EQ(report.sigma, 0.3 * report.spacing);
  EXPECT_EQ(report.outliers, 0u);
  for (int axis = 0; axis < 3; ++axis) {
    double sum = 0.0, sum2 = 0.0;
    for (std::size_t i = 0; i < plane.size(); ++i) {
      const double d = noisy.xyz[3 * i + axis] - plane.xyz[3 * i + axis];
      sum += d;
      sum2 += d * d;
    }
    const double n = static_cast<double>(plane.size());
    const double mean = sum / n;
    const double sigma = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(sigma, report.sigma, 0.01 * report.sigma) << "axis " << axis;
    EXPECT_NEAR(mean, 0.0, 0.02 * report.sigma) << "axis " << axis;  // 4 standard errors
  }
}

TEST(SynthPerturb, OutlierCountIsExactAndTheyFillTheBoundingBox) {
  const PointCloud plane = plane_grid(100, 0.5);  // box 49.5 x 49.5 x 0
  PerturbOptions options;
  options.outliers = 0.05;
  const PointCloud out = g2s::perturb_cloud(plane, options);
  ASSERT_EQ(out.size(), 10'000u + 500u);
  // Without noise the input points come first, unchanged.
  for (std::size_t k = 0; k < plane.xyz.size(); ++k) ASSERT_EQ(out.xyz[k], plane.xyz[k]);
  int low_half = 0;
  for (std::size_t i = plane.size(); i < out.size(); ++i) {
    EXPECT_GE(out.xyz[3 * i], 5e5);
    EXPECT_LE(out.xyz[3 * i], 5e5 + 49.5);
    EXPECT_GE(out.xyz[3 * i + 1], 4e6);
    EXPECT_LE(out.xyz[3 * i + 1], 4e6 + 49.5);
    EXPECT_EQ(out.xyz[3 * i + 2], 100.0);
    low_half += out.xyz[3 * i] < 5e5 + 24.75;
  }
  EXPECT_NEAR(low_half, 250, 50);  // uniform: about half below the middle (5 sigma)
  // round(outliers * n): 0.00005 * 10,000 = 0.5 rounds away from zero, 0.00004 to 0.
  options.outliers = 0.00005;
  EXPECT_EQ(g2s::perturb_cloud(plane, options).size(), 10'001u);
  options.outliers = 0.00004;
  EXPECT_EQ(g2s::perturb_cloud(plane, options).size(), 10'000u);
}

TEST(SynthPerturb, DependsOnlyOnTheSeed) {
  const PointCloud plane = plane_grid(60, 0.1);
  PerturbOptions options;
  options.noise = 0.2;
  options.outliers = 0.1;
  options.seed = 3;
  const PointCloud a = g2s::perturb_cloud(plane, options);
  EXPECT_EQ(a.xyz, g2s::perturb_cloud(plane, options).xyz);
  options.seed = 4;
  const PointCloud b = g2s::perturb_cloud(plane, options);
  ASSERT_EQ(a.size(), b.size());
  // Every point moves (outliers keep z = 100: the plane's box is flat).
  std::size_t same = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    same += a.xyz[3 * i] == b.xyz[3 * i] && a.xyz[3 * i + 1] == b.xyz[3 * i + 1];
  EXPECT_EQ(same, 0u);
}

TEST(SynthPerturb, RejectsBadOptionsAndCloudsWithoutASpacing) {
  const PointCloud plane = plane_grid(4, 1.0);
  PerturbOptions options;
  options.noise = -0.1;
  EXPECT_EQ(expect_error(plane, options), static_cast<int>(g2s::Exit::usage));
  options.noise = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(expect_error(plane, options), static_cast<int>(g2s::Exit::usage));
  options.noise = 0.0;
  options.outliers = 101.0;
  EXPECT_EQ(expect_error(plane, options), static_cast<int>(g2s::Exit::usage));
  options.outliers = 0.1;
  EXPECT_EQ(expect_error(PointCloud{}, options), static_cast<int>(g2s::Exit::bad_input));
  EXPECT_EQ(expect_error(PointCloud{{1, 2, 3}}, options), static_cast<int>(g2s::Exit::bad_input));
  // Duplicates count once: two copies of a point have no spacing either.
  EXPECT_EQ(expect_error(PointCloud{{1, 2, 3, 1, 2, 3}}, options),
            static_cast<int>(g2s::Exit::bad_input));
  EXPECT_EQ(expect_error(plane, options), 0);
}

using SynthPerturbFiles = g2s::test_support::CliTest;

// `g2s synth --from` writes perturb_cloud's points as float, and refuses to mix a SHAPE in.
TEST_F(SynthPerturbFiles, CommandLine) {
  // A grid near the origin, so that float keeps its coordinates.
  PointCloud grid;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j) grid.xyz.insert(grid.xyz.end(), {i * 0.5, j * 0.5, 1.0});
  const auto input = dir_ / "in.ply";
  g2s::PlyPointWriter writer(input, grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i)
    writer.add(static_cast<float>(grid.xyz[3 * i]), static_cast<float>(grid.xyz[3 * i + 1]),
               static_cast<float>(grid.xyz[3 * i + 2]));
  writer.finish();
  const auto output_path = dir_ / "out.ply";
  const std::string output = run({"synth", "--from", input.string(), "--noise", "0.2", "--outliers",
                                  "0.1", "--seed", "9", "-o", output_path.string()},
                                 0);
  EXPECT_NE(output.find("900 points + 90 outliers, spacing 0.5,"), std::string::npos) << output;
  PerturbOptions options;
  options.noise = 0.2;
  options.outliers = 0.1;
  options.seed = 9;
  const PointCloud expected = g2s::perturb_cloud(grid, options);
  const PointCloud written = g2s::read_points(output_path);
  ASSERT_EQ(written.size(), expected.size());
  for (std::size_t k = 0; k < expected.xyz.size(); ++k)
    ASSERT_EQ(written.xyz[k], static_cast<double>(static_cast<float>(expected.xyz[k])));

  const std::string bad = (dir_ / "bad.ply").string();
  run({"synth", "torus", "--from", input.string(), "-o", bad}, 2);
  run({"synth", "--from", input.string(), "-n", "100", "-o", bad}, 2);
  run({"synth", "--noise", "0.1", "-o", bad}, 2);
  run({"synth", "--from", (dir_ / "missing.ply").string(), "-o", bad}, 3);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.ply"));
}

}  // namespace
