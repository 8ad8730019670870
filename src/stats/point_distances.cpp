// Point-to-mesh distances of compute_stats (point_distances.hpp): how far the input points the
// mesh leaves out lie from it, in sampling spacings, so that "left out but close to the surface"
// can be told from "an outlier" or "a hole". Two box trees (box_tree.hpp), one over the cloud's
// points for the spacing, one over the mesh's triangles for the distances, queried in parallel;
// a point's distance to a triangle is that to its closest point, computed in double.
#include "stats/point_distances.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "common/sample_spacing.hpp"
#include "common/vec3.hpp"
#include "stats/box_tree.hpp"

namespace g2s::stats {
namespace {

constexpr std::size_t kSpacingSample = 65536;
// A point left out with fewer than two other points within this many spacings is isolated: no
// triangle whose sides are that short can have it as a corner (the same two spacings within
// which a left-out surface point should lie of the mesh).
constexpr double kIsolationSpacings = 2.0;

bool finite(const double* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

Vec3 at(const double* p) {
  return {p[0], p[1], p[2]};
}

// The cloud's finite points in a box tree.
struct PointTree {
  explicit PointTree(const PointCloud& cloud)
      : points(finite_points(cloud)), tree(points.size(), [&](std::size_t i) {
          const double* p = &cloud.xyz[3 * std::size_t{points[i]}];
          return BoxTree::Box{{p[0], p[1], p[2]}, {p[0], p[1], p[2]}};
        }) {}
  static std::vector<std::uint32_t> finite_points(const PointCloud& cloud) {
    std::vector<std::uint32_t> out;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (finite(&cloud.xyz[3 * i])) out.push_back(static_cast<std::uint32_t>(i));
    }
    return out;
  }
  std::vector<std::uint32_t> points;  // indices into the cloud
  BoxTree tree;
};

// Whether fewer than two other points (at other positions) lie within `radius` of point q: then
// no triangle with sides of at most `radius` can have it as a corner.
bool isolated(const PointCloud& cloud, const PointTree& near, const double* q, double radius) {
  const Vec3 p = at(q);
  int others = 0;
  near.tree.for_each_near(q, radius, [&](std::uint32_t i) {
    const double d = norm(at(&cloud.xyz[3 * std::size_t{near.points[i]}]) - p);
    others += d > 0.0 && d <= radius;
  });
  return others < 2;
}

// Median spacing distance (common/sample_spacing.hpp) of every k-th point, to the points at other
// positions.
double median_spacing(const PointCloud& cloud, const PointTree& near) {
  const std::vector<std::uint32_t>& points = near.points;
  const BoxTree& tree = near.tree;
  if (points.size() < 2) return 0.0;
  const std::size_t step = (points.size() + kSpacingSample - 1) / kSpacingSample;
  std::vector<NearestThree> samples((points.size() + step - 1) / step);
  tbb::parallel_for(std::size_t{0}, samples.size(), [&](std::size_t s) {
    const double* q = &cloud.xyz[3 * std::size_t{points[s * step]}];
    const Vec3 p = at(q);
    samples[s] = tree.nearest_three(q, [&](std::uint32_t i) {
      const double d = norm(at(&cloud.xyz[3 * std::size_t{points[i]}]) - p);
      return d == 0.0 ? -1.0 : d;
    });
  });
  // Points whose every neighbour is at their own position have no spacing.
  std::vector<double> distances = spacing_distances(samples).distances;
  if (distances.empty()) return 0.0;
  const auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return *middle;
}

}  // namespace

void measure_point_distances(std::span<const Triangle> triangles, const double* xyz,
                             std::span<const Index> rep, const PointCloud& cloud,
                             std::span<const std::uint64_t> off_mesh, MeshStats& stats) {
  auto corner = [&](Index w) { return xyz + 3 * std::size_t{rep[w]}; };
  std::vector<std::uint32_t> usable;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    if (tri[0] != kNoIndex && finite(corner(tri[0])) && finite(corner(tri[1])) &&
        finite(corner(tri[2]))) {
      usable.push_back(static_cast<std::uint32_t>(t));
    }
  }
  const PointTree near(cloud);
  stats.spacing = median_spacing(cloud, near);
  if (usable.empty() || !(stats.spacing > 0.0)) return;
  stats.has_distances = true;
  stats.surface_coverage = stats.coverage;
  if (off_mesh.empty()) return;  // every point is a vertex: nothing to measure

  const BoxTree tree(usable.size(), [&](std::size_t i) {
    const Triangle& tri = triangles[usable[i]];
    BoxTree::Box box;
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = std::min({corner(tri[0])[k], corner(tri[1])[k], corner(tri[2])[k]});
      box.hi[k] = std::max({corner(tri[0])[k], corner(tri[1])[k], corner(tri[2])[k]});
    }
    return box;
  });
  std::vector<double> distance(off_mesh.size());
  std::vector<std::uint8_t> alone(off_mesh.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, off_mesh.size(), 256), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const double* q = &cloud.xyz[3 * off_mesh[i]];
      if (!finite(q)) {
        distance[i] = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      alone[i] = isolated(cloud, near, q, kIsolationSpacings * stats.spacing);
      const Vec3 p = at(q);
      distance[i] = tree.nearest(q, [&](std::uint32_t item) {
        const Triangle& tri = triangles[usable[item]];
        return norm(
            closest_on_triangle(p, at(corner(tri[0])), at(corner(tri[1])), at(corner(tri[2]))) - p);
      }) / stats.spacing;
    }
  });
  stats.off_mesh_isolated = static_cast<std::uint64_t>(std::count(alone.begin(), alone.end(), 1));
  for (std::size_t i = 0; i < distance.size(); ++i) {
    stats.off_mesh_far_not_isolated += !alone[i] && distance[i] > kIsolationSpacings;
  }
  const std::uint64_t surface_points = stats.input_points - stats.off_mesh_isolated;
  stats.surface_coverage = surface_points > 0 ? static_cast<double>(stats.covered_points) /
                                                    static_cast<double>(surface_points)
                                              : 0.0;
  distance.erase(
      std::remove_if(distance.begin(), distance.end(), [](double d) { return std::isnan(d); }),
      distance.end());
  std::sort(distance.begin(), distance.end());
  stats.off_mesh_points = distance.size();
  for (const double d : distance) {
    stats.off_mesh_within_1 += d <= 1.0;
    stats.off_mesh_within_2 += d <= 2.0;
    stats.off_mesh_within_4 += d <= 4.0;
  }
  stats.off_mesh_beyond_4 = distance.size() - stats.off_mesh_within_4;
  auto quantile = [&](double q) {
    if (distance.empty()) return 0.0;
    return distance[static_cast<std::size_t>(q * static_cast<double>(distance.size() - 1))];
  };
  stats.off_mesh_median = quantile(0.5);
  stats.off_mesh_p90 = quantile(0.9);
  stats.off_mesh_p99 = quantile(0.99);
  stats.off_mesh_max = quantile(1.0);
}

}  // namespace g2s::stats
