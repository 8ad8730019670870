// The mesher on the real scans in $G2S_DATA_DIR (default ../shared/data), through mesh_cloud:
// the same tiles, growth, seams and clean-up as `g2s mesh`. Every output is
// measured with compute_stats and must be manifold, consistently oriented and free of
// duplicates on every cloud; closed scans must also be covered and have ~2 triangles per point.
// On open and raw scans, boundary edges, holes and coverage are held to recorded baselines so
// that they do not get worse.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <ostream>
#include <set>
#include <span>
#include <string>

#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/stats.hpp"
#include "support/clean_mesh.hpp"
#include "support/cli.hpp"

namespace {

using g2s::test_support::data_dir;

struct Baseline {
  const char* name;
  bool closed;
  // Limits for open and raw scans: measured values plus a margin for deliberate trade-offs.
  double min_coverage;
  std::uint64_t max_boundary_edges;
  std::uint64_t max_holes;
  // Issue 16's floor on the coverage of the points that can lie on a surface (isolated points,
  // with fewer than two others within two spacings, aside): 99.5% on clean single-layer scans,
  // 97% on the noisy and layered ones.
  double min_surface_coverage;
};

// So that test listings name the cloud rather than dump the struct's bytes.
void PrintTo(const Baseline& b, std::ostream* os) {
  *os << b.name;
}

class RealScan : public ::testing::TestWithParam<Baseline> {};

TEST_P(RealScan, MeshIsManifoldOrientedAndMeetsItsBaseline) {
  const Baseline& b = GetParam();
  const std::filesystem::path path = data_dir() / (std::string(b.name) + ".ply");
  G2S_SKIP_WITHOUT_DATA(path);
  const g2s::PointCloud cloud = g2s::read_points(path);
  ASSERT_GT(cloud.size(), 0u);
  g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud);
  const g2s::IndexedMesh indexed{cloud.xyz, std::move(mesh.triangles)};
  const g2s::MeshStats s = g2s::compute_stats(indexed, &cloud);
  const double per_point = static_cast<double>(s.triangles) / static_cast<double>(cloud.size());
  std::printf(
      "%s: %zu points, %llu triangles (%.3f per point), coverage %.4f, boundary edges "
      "%llu, holes %llu, components %llu\n",
      b.name, cloud.size(), static_cast<unsigned long long>(s.triangles), per_point, s.coverage,
      static_cast<unsigned long long>(s.boundary_edges), static_cast<unsigned long long>(s.holes),
      static_cast<unsigned long long>(s.components));
  RecordProperty("triangles", std::to_string(s.triangles));
  RecordProperty("boundary_edges", std::to_string(s.boundary_edges));
  RecordProperty("holes", std::to_string(s.holes));
  RecordProperty("coverage", std::to_string(s.coverage));

  // Crossings counted exactly, as g2s stats counts them: the mesher leaves none.
  g2s::test_support::expect_clean_mesh(s);
  if (b.closed) {
    EXPECT_GE(s.coverage, 0.995);
    EXPECT_GE(per_point, 1.9);
    EXPECT_LE(per_point, 2.02);
  }
  EXPECT_GE(s.coverage, b.min_coverage);
  ASSERT_TRUE(s.has_distances);
  std::printf(
      "%s: surface coverage %.4f (%llu isolated points aside), %llu points left out "
      "farther than 2 spacings that are not isolated\n",
      b.name, s.surface_coverage, static_cast<unsigned long long>(s.off_mesh_isolated),
      static_cast<unsigned long long>(s.off_mesh_far_not_isolated));
  EXPECT_GE(s.surface_coverage, b.min_surface_coverage);
  // A point left out lies within two spacings of the mesh unless it is isolated: all but a few
  // in ten thousand (measured: 0 to 65 on these scans).
  EXPECT_LE(s.off_mesh_far_not_isolated, cloud.size() / 1000);
  EXPECT_LE(s.boundary_edges, b.max_boundary_edges);
  EXPECT_LE(s.holes, b.max_holes);
}

// Closing three-edge gaps after growth (MeshOptions::close_gaps) must leave fewer holes and
// boundary edges than the paper's G2S alone, and no defect, on noisy scans of each kind.
TEST(RealScanGaps, ClosingGapsLeavesFewerHolesAndNoDefect) {
  for (const char* name : {"raw-bunny", "open-table-mug-stereo", "open-lion-photogrammetry"}) {
    SCOPED_TRACE(name);
    const std::filesystem::path path = data_dir() / (std::string(name) + ".ply");
    G2S_SKIP_WITHOUT_DATA(path);
    const g2s::PointCloud cloud = g2s::read_points(path);
    g2s::MeshStats s[2];
    for (const bool close : {false, true}) {
      g2s::PipelineOptions options;
      options.mesh.close_gaps = close;
      if (!close) options.mesh.max_hole_edges = 0;  // hole filling closes such gaps too
      options.mesh.max_hole_rings = 0;              // widened holes leave points out
      g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud, options);
      s[close] = g2s::compute_stats({cloud.xyz, std::move(mesh.triangles)}, &cloud);
      EXPECT_EQ(s[close].non_manifold_edges, 0u);
      EXPECT_EQ(s[close].non_manifold_vertices, 0u);
      EXPECT_EQ(s[close].orientation_conflicts, 0u);
      EXPECT_EQ(s[close].duplicate_triangles, 0u);
      EXPECT_EQ(s[close].degenerate_triangles, 0u);
    }
    EXPECT_GT(s[1].triangles, s[0].triangles);
    EXPECT_LT(s[1].boundary_edges, s[0].boundary_edges);
    EXPECT_LT(s[1].holes, s[0].holes);
    // Closing gaps uses no new point; which triangles survive the crossing search may shift a
    // few points in or out.
    EXPECT_GE(s[1].coverage, s[0].coverage - 0.001);
  }
}

// Widening the holes that cannot be filled over their own points (MeshOptions::max_hole_rings)
// must leave fewer holes and no defect, and leave out only points close to the surface: the
// grower allows 3 of the tile's spacings, and on a cloud of two densities (table-mug) a sparse
// tile's spacing is larger than the cloud's, which the statistics use, so a few of them are
// farther than 4 of those (measured: 97-100% within 4 on these scans).
TEST(RealScanGaps, WideningHolesLeavesFewerHolesAndOnlyPointsNearTheSurfaceOut) {
  for (const char* name :
       {"raw-bunny", "open-table-mug-stereo", "open-lion-photogrammetry", "open-autzen-lidar"}) {
    SCOPED_TRACE(name);
    const std::filesystem::path path = data_dir() / (std::string(name) + ".ply");
    G2S_SKIP_WITHOUT_DATA(path);
    const g2s::PointCloud cloud = g2s::read_points(path);
    g2s::MeshStats s[2];
    for (const int rings : {0, g2s::MeshOptions{}.max_hole_rings}) {
      g2s::PipelineOptions options;
      options.mesh.max_hole_rings = rings;
      g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud, options);
      g2s::MeshStats& m = s[rings > 0];
      m = g2s::compute_stats({cloud.xyz, std::move(mesh.triangles)}, &cloud);
      g2s::test_support::expect_clean_mesh(m);
      ASSERT_TRUE(m.has_distances);
    }
    std::printf("%s: holes %llu -> %llu, points left out %llu -> %llu\n", name,
                static_cast<unsigned long long>(s[0].holes),
                static_cast<unsigned long long>(s[1].holes),
                static_cast<unsigned long long>(s[0].off_mesh_points),
                static_cast<unsigned long long>(s[1].off_mesh_points));
    EXPECT_LT(static_cast<double>(s[1].holes), 0.95 * static_cast<double>(s[0].holes));
    ASSERT_GE(s[1].off_mesh_points, s[0].off_mesh_points);
    const auto more_left_out = static_cast<double>(s[1].off_mesh_points - s[0].off_mesh_points);
    const auto more_within_4 =
        static_cast<double>(s[1].off_mesh_within_4) - static_cast<double>(s[0].off_mesh_within_4);
    EXPECT_GE(more_within_4, 0.9 * more_left_out);
  }
}

// A pinhole of raw-bunny that the surface folds over: triangles of its corners' fans lie over
// the hole, so every filling crosses one, and widening ring by ring meets more folds before the
// hole closes. The narrow widening (the ring across the loop's edges and the folded triangles;
// docs/algorithm.md, "Hole filling") fills it. The points within 15 mm of it, meshed as g2s mesh
// meshes them: no open edge within 6 mm (without the narrow widening, 9 open edges stay there)
// and no defect. The crop holds the fold as growth makes it now; a change to growth may move it,
// and then another pinhole the narrow widening closes serves (bench/results/2026-12-07-session40.md
// tells how this one was found).
TEST(RealScanGaps, APinholeUnderAFoldIsFilled) {
  const std::filesystem::path path = data_dir() / "raw-bunny.ply";
  G2S_SKIP_WITHOUT_DATA(path);
  const g2s::PointCloud cloud = g2s::read_points(path);
  const double centre[3] = {0.020481444444444444, 0.121161, -0.006624222222222222};
  const auto distance2 = [&](std::span<const double> xyz, std::size_t i) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (xyz[3 * i + k] - centre[k]) * (xyz[3 * i + k] - centre[k]);
    return d2;
  };
  g2s::PointCloud crop;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (distance2(cloud.xyz, i) < 0.015 * 0.015) {
      crop.xyz.insert(crop.xyz.end(), cloud.xyz.begin() + 3 * i, cloud.xyz.begin() + 3 * i + 3);
    }
  }
  ASSERT_EQ(crop.size(), 6021u);
  g2s::PipelineMesh mesh = g2s::mesh_cloud(crop);
  std::set<std::pair<g2s::Index, g2s::Index>> edges;
  for (const g2s::Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) edges.insert({t[k], t[(k + 1) % 3]});
  }
  std::size_t open_near = 0;
  for (const auto& [u, v] : edges) {
    if (!edges.contains({v, u}) && distance2(crop.xyz, u) < 0.006 * 0.006 &&
        distance2(crop.xyz, v) < 0.006 * 0.006) {
      ++open_near;
    }
  }
  EXPECT_EQ(open_near, 0u);
  g2s::test_support::expect_clean_mesh(
      g2s::compute_stats({crop.xyz, std::move(mesh.triangles)}, &crop));
}

// Coordinates finer than float, as a double PLY or a LAS file's scaled integers give them: the
// mesher grows in float, but judges crossings on the coordinates the output holds
// (detail::CrossingPositions), so the mesh it writes has none. table-mug turned in double about a
// slanted axis: judged on its floats, its mesh had 238 crossing pairs.
TEST(RealScanPrecision, ACloudFinerThanFloatMeshesWithoutCrossings) {
  const std::filesystem::path path = data_dir() / "open-table-mug-stereo.ply";
  G2S_SKIP_WITHOUT_DATA(path);
  g2s::PointCloud cloud = g2s::read_points(path);
  // Rodrigues' rotation by 0.7 rad about (1, 2, 3) / sqrt(14).
  const double angle = 0.7, norm = std::sqrt(14.0);
  const double axis[3] = {1 / norm, 2 / norm, 3 / norm};
  const double c = std::cos(angle), s = std::sin(angle);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    double* p = &cloud.xyz[3 * i];
    const double along = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
    const double across[3] = {axis[1] * p[2] - axis[2] * p[1], axis[2] * p[0] - axis[0] * p[2],
                              axis[0] * p[1] - axis[1] * p[0]};
    for (int k = 0; k < 3; ++k) p[k] = p[k] * c + across[k] * s + axis[k] * along * (1 - c);
  }
  g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud);
  const g2s::MeshStats stats = g2s::compute_stats({cloud.xyz, std::move(mesh.triangles)}, &cloud);
  g2s::test_support::expect_clean_mesh(stats);
  EXPECT_GT(stats.coverage, 0.99);
}

// Baselines measured through mesh_cloud (the tiled path `g2s mesh` runs, default options and
// memory budget) after the surface finishing step (no crossings, holes filled): boundary edges and
// holes plus 5% (rounded up; one more hole where the count is tiny), coverage minus 0.002. Lower
// them when the mesher improves. closed-bunny-zipper is closed now that the small holes the scan
// leaves in its base are filled. Widened holes and removed scraps (MeshOptions::max_hole_rings)
// leave out points near the surface: the noisy scans' coverage fell by 0.1 to 0.8 points.
// raw-bunny's were measured again (780 -> 817 holes) when gaps between two fans of a point
// stopped being widened before the non-manifold pass (docs/algorithm.md, "Hole filling"), and
// raw-bunny, table-mug, lion, autzen and alpe again when widened borders took in the pockets
// they close around (holes 814 -> 675 on raw-bunny, coverage 0.9857 -> 0.9827), and once more
// when a widened border could grow by six edges a ring and holes whose widening met a filling of
// the same round were tried again (holes 662 -> 567 on raw-bunny, coverage 0.9827 -> 0.9795), and
// when growth began refusing crossing triangles instead of removing them afterwards (holes 567 ->
// 560 on raw-bunny, 211 -> 201 on autzen, 27,017 -> 25,657 on alpe), and when holes under a fold
// were widened by just the fold (560 -> 551 on raw-bunny, 384 -> 380 on lion, 58 -> 57 on
// table-mug, 25,657 -> 25,437 on alpe).
INSTANTIATE_TEST_SUITE_P(
    SharedData, RealScan,
    ::testing::Values(Baseline{"closed-kitten", true, 0.995, 0, 0, 0.995},
                      Baseline{"closed-bunny-zipper", true, 0.995, 8, 1, 0.995},
                      Baseline{"open-bunny-scan-bun000", false, 0.9977, 690, 7, 0.995},
                      Baseline{"raw-bunny", false, 0.9774, 15960, 579, 0.97},
                      Baseline{"open-table-mug-stereo", false, 0.9918, 4921, 60, 0.97},
                      Baseline{"open-lion-photogrammetry", false, 0.9911, 16127, 399, 0.97},
                      Baseline{"open-autzen-lidar", false, 0.9904, 9442, 211, 0.995},
                      Baseline{"open-alpe-selle-photogrammetry", false, 0.9759, 2419583, 26709,
                               0.97}),
    [](const ::testing::TestParamInfo<Baseline>& param) {
      std::string name = param.param.name;
      for (char& c : name) {
        if (c == '-') c = '_';
      }
      return name;
    });

}  // namespace
