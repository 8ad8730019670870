// Samplings that none of the shared scans has, as real scanners make them: scan lines ten times
// closer along than across, a density that falls a hundredfold across the cloud, two sheets a
// third of a spacing apart, an exact lattice (four points on a circle everywhere), and a
// cylinder whose points scatter a whole spacing off it. Each is meshed through mesh_cloud (the
// tiled path `g2s mesh` runs, in several tiles) and measured by compute_stats, as `g2s stats`
// measures: no mesh may have a defect, and the surface must still be meshed (at least 97% of
// the points, the bound issue 16 sets for noisy scans; all of them on the lattice). And stray
// points far from a georeferenced scan, which must change nothing.
// docs/algorithm.md §8 gives what each sampling costs in holes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include "g2s/pipeline.hpp"
#include "g2s/stats.hpp"
#include "support/clean_mesh.hpp"

namespace {

// Uniform and Gaussian draws computed here from the engine's integers, so that the clouds do
// not depend on a library's distributions.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : engine_(seed) {}
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  double gaussian(double sigma) {  // Box-Muller
    const double u = uniform(0x1.0p-53, 1.0), v = uniform(0.0, 1.0);
    return sigma * std::sqrt(-2 * std::log(u)) * std::cos(2 * std::numbers::pi * v);
  }

 private:
  std::mt19937_64 engine_;
};

void add(g2s::PointCloud& cloud, double x, double y, double z) {
  cloud.xyz.insert(cloud.xyz.end(), {x, y, z});
}

g2s::MeshStats mesh_and_measure(const std::string& name, const g2s::PointCloud& cloud) {
  // Tiles of a tenth of the cloud: seams cross every pattern.
  g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud, {}, cloud.size() / 10);
  const g2s::MeshStats s = g2s::compute_stats({cloud.xyz, std::move(mesh.triangles)}, &cloud);
  std::printf("%s: %zu points, %llu triangles, %llu holes, %llu boundary edges, coverage %.4f\n",
              name.c_str(), cloud.size(), static_cast<unsigned long long>(s.triangles),
              static_cast<unsigned long long>(s.holes),
              static_cast<unsigned long long>(s.boundary_edges), s.coverage);
  g2s::test_support::expect_clean_mesh(s);
  return s;
}

TEST(SamplingPatterns, ScanLinesTenTimesCloserAlongThanAcross) {
  // Profiles 0.1 apart, points 0.01 apart along them (mobile and airborne LiDAR lines), over a
  // gently curved ground, with jitter.
  Draw draw(1);
  g2s::PointCloud cloud;
  for (int line = 0; line < 100; ++line) {
    for (int step = 0; step < 600; ++step) {
      const double x = 0.01 * step + draw.gaussian(0.002), y = 0.1 * line + draw.gaussian(0.01);
      add(cloud, x, y, std::sin(0.5 * x) + std::cos(0.3 * y) + draw.gaussian(0.005));
    }
  }
  const g2s::MeshStats s = mesh_and_measure("scan lines", cloud);
  EXPECT_GE(s.coverage, 0.97);
}

TEST(SamplingPatterns, DensityFallingAHundredfold) {
  // Density proportional to 1 / (1 + x)^2 over [0, 10]^2 (a scanner's fall-off with range):
  // 121 times denser at x = 0 than at x = 10. Drawn by inverting the distribution along x.
  Draw draw(2);
  g2s::PointCloud cloud;
  for (int i = 0; i < 100000; ++i) {
    const double x = 1 / (1 - draw.uniform(0, 1) * (1 - 1.0 / 11)) - 1, y = draw.uniform(0, 10);
    add(cloud, x, y, 0.3 * std::sin(0.7 * x) * std::cos(0.5 * y));
  }
  const g2s::MeshStats s = mesh_and_measure("density gradient", cloud);
  EXPECT_GE(s.coverage, 0.97);
}

TEST(SamplingPatterns, TwoSheetsAThirdOfASpacingApart) {
  // Two overlapping scans of one plate, offset by a third of their spacing: one surface.
  Draw draw(3);
  g2s::PointCloud cloud;
  const int n = 60000;
  const double spacing = 2 / std::sqrt(n / 2.0);
  for (int i = 0; i < n; ++i) {
    add(cloud, draw.uniform(0, 2), draw.uniform(0, 2), i % 2 == 0 ? 0.0 : spacing / 3);
  }
  const g2s::MeshStats s = mesh_and_measure("two sheets", cloud);
  EXPECT_GE(s.coverage, 0.97);
}

TEST(SamplingPatterns, ExactLatticeOfCocircularPoints) {
  // Every square of the lattice has its four corners on one circle: each choice of diagonal is
  // a tie the mesher must break the same way everywhere, with no crossing and no hole.
  g2s::PointCloud cloud;
  for (int i = 0; i < 200; ++i) {
    for (int j = 0; j < 200; ++j) add(cloud, i, j, 0);
  }
  const g2s::MeshStats s = mesh_and_measure("lattice", cloud);
  EXPECT_EQ(s.coverage, 1.0);
  EXPECT_EQ(s.holes, 1u);  // the border
}

TEST(SamplingPatterns, StrayPointsAtTheOriginOfAGeoreferencedScanChangeNothing) {
  // A terrain in UTM coordinates (x about 500,000 m, y about 5,000,000 m, points 0.25 m apart),
  // and the same with three invalid returns at (0, 0, 0), as some LAS writers leave them. The
  // tiles' float frames used to reach to the origin: float steps of 0.03 m in x and 0.5 m in y
  // merged 182 points and cost 23% of the triangles. Now the strays get a tile of their own
  // (kStrayGap) and the terrain is meshed as it is alone.
  Draw draw(5);
  g2s::PointCloud terrain;
  for (int i = 0; i < 200; ++i) {
    for (int j = 0; j < 200; ++j) {
      const double x = 0.25 * i, y = 0.25 * j;
      add(terrain, 500000.123 + x, 5000000.456 + y,
          300 + 0.5 * std::sin(x / 7) + draw.gaussian(0.001));
    }
  }
  g2s::PointCloud with_strays = terrain;
  for (int k = 0; k < 3; ++k) add(with_strays, 0, 0, 0);
  const g2s::MeshStats alone = mesh_and_measure("terrain", terrain);
  const g2s::MeshStats s = mesh_and_measure("terrain and strays", with_strays);
  EXPECT_EQ(s.triangles, alone.triangles);
  EXPECT_EQ(s.boundary_edges, alone.boundary_edges);
  EXPECT_EQ(s.covered_points, alone.covered_points);
}

TEST(SamplingPatterns, CylinderScatteredAWholeSpacingOffTheSurface) {
  // Radial noise of one spacing (a layer about four spacings thick): the mesher folds through
  // it, leaving holes, but the mesh stays free of defects and takes the 97% of points that
  // issue 16 asks of noisy scans.
  Draw draw(4);
  g2s::PointCloud cloud;
  const int n = 60000;
  const double spacing = std::sqrt(2 * std::numbers::pi * 3 / n);
  for (int i = 0; i < n; ++i) {
    const double angle = draw.uniform(0, 2 * std::numbers::pi), r = 1 + draw.gaussian(spacing);
    add(cloud, r * std::cos(angle), r * std::sin(angle), draw.uniform(0, 3));
  }
  const g2s::MeshStats s = mesh_and_measure("thick cylinder", cloud);
  EXPECT_GE(s.coverage, 0.97);
}

}  // namespace
