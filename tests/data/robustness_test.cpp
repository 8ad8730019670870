// The paper's claim for noisy input (Di Angelo & Giaccari 2011, §5, Tables 3 and 4): with
// Gaussian noise or outliers added to the Stanford Bunny, G2S still produces no non-manifold
// vertex. The hardest cases of docs/robustness.md, through mesh_cloud (the tiled path `g2s mesh`
// runs): sigma = 0.5 mean
// spacings and 20% outliers in the bounding box. No non-manifold edge or vertex, no orientation
// conflict, and (beyond the paper) no crossing, duplicate or degenerate triangle, as g2s stats
// counts them. scripts/robustness.sh measures the whole series.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/stats.hpp"
#include "g2s/synth.hpp"
#include "support/clean_mesh.hpp"
#include "support/cli.hpp"

namespace {

std::filesystem::path bunny_path() {
  return g2s::test_support::data_dir() / "closed-bunny-zipper.ply";
}

g2s::MeshStats mesh_perturbed_bunny(const g2s::PerturbOptions& options) {
  const g2s::PointCloud clean = g2s::read_points(bunny_path());
  const g2s::PointCloud cloud = g2s::perturb_cloud(clean, options);
  g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud);
  const g2s::MeshStats s = g2s::compute_stats({cloud.xyz, std::move(mesh.triangles)}, &cloud);
  std::printf("%llu points, %llu triangles, %llu boundary edges\n",
              static_cast<unsigned long long>(cloud.size()),
              static_cast<unsigned long long>(s.triangles),
              static_cast<unsigned long long>(s.boundary_edges));
  return s;
}

void expect_manifold(const g2s::MeshStats& s, std::uint64_t min_triangles) {
  g2s::test_support::expect_clean_mesh(s);
  // The surface is still meshed (the clean bunny gives 71,886 triangles; measured through
  // mesh_cloud: 69,910 with the noise, 76,553 with the outliers, 66,628 with both).
  EXPECT_GE(s.triangles, min_triangles);
}

TEST(Robustness, BunnyWithNoiseHalfTheSpacingStaysManifold) {
  G2S_SKIP_WITHOUT_DATA(bunny_path());
  g2s::PerturbOptions options;
  options.noise = 0.5;
  expect_manifold(mesh_perturbed_bunny(options), 65'000);
}

TEST(Robustness, BunnyWithTwentyPercentOutliersStaysManifold) {
  G2S_SKIP_WITHOUT_DATA(bunny_path());
  g2s::PerturbOptions options;
  options.outliers = 0.2;
  expect_manifold(mesh_perturbed_bunny(options), 70'000);
}

TEST(Robustness, BunnyWithNoiseOfASpacingAndOutliersHasNoDefect) {
  G2S_SKIP_WITHOUT_DATA(bunny_path());
  g2s::PerturbOptions options;
  options.noise = 1.0;
  options.outliers = 0.1;
  expect_manifold(mesh_perturbed_bunny(options), 60'000);
}

}  // namespace
