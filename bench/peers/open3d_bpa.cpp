// Peer driver: Open3D's ball pivoting (Bernardini et al., 1999) as Open3D's surface
// reconstruction tutorial runs it: normals from EstimateNormals with a hybrid KD-tree search
// (radius and 30 neighbours, as the point cloud tutorial), then
// TriangleMesh::CreateFromPointCloudBallPivoting over four doubling radii. The tutorial's radii
// (0.005-0.04) and normal radius (0.1) are absolute lengths for its clouds; here they are
// multiples of the cloud's mean nearest-neighbour spacing (why: bench/peers/README.md). Open3D
// runs its loops with OpenMP: OMP_NUM_THREADS sets its threads. Usage and output:
// peer_driver.hpp.
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include <memory>
#include <numeric>
#include <vector>

#include "peer_driver.hpp"

namespace {

constexpr double kNormalRadiusSpacings = 2.0;  // the tutorial's 0.1 over its 0.05 voxel spacing
constexpr int kNormalNeighbours = 30;
constexpr double kBallRadiiSpacings[] = {1, 2, 4, 8};  // the tutorial's 0.005-0.04 over ~0.005

g2s::IndexedMesh reconstruct(g2s::PointCloud& input) {
  open3d::geometry::PointCloud cloud;
  cloud.points_.resize(input.size());
  for (std::size_t i = 0; i < input.size(); ++i) {
    cloud.points_[i] = {input.xyz[3 * i], input.xyz[3 * i + 1], input.xyz[3 * i + 2]};
  }
  const std::vector<double> nearest = cloud.ComputeNearestNeighborDistance();
  const double spacing =
      std::accumulate(nearest.begin(), nearest.end(), 0.0) / static_cast<double>(nearest.size());
  cloud.EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(kNormalRadiusSpacings * spacing,
                                                                  kNormalNeighbours));
  std::vector<double> radii;
  for (double r : kBallRadiiSpacings) radii.push_back(r * spacing);
  const std::shared_ptr<open3d::geometry::TriangleMesh> result =
      open3d::geometry::TriangleMesh::CreateFromPointCloudBallPivoting(cloud, radii);

  g2s::IndexedMesh mesh;
  mesh.xyz.reserve(3 * result->vertices_.size());
  for (const Eigen::Vector3d& v : result->vertices_)
    mesh.xyz.insert(mesh.xyz.end(), {v.x(), v.y(), v.z()});
  mesh.triangles.reserve(result->triangles_.size());
  for (const Eigen::Vector3i& t : result->triangles_) {
    mesh.triangles.push_back({static_cast<g2s::Index>(t.x()), static_cast<g2s::Index>(t.y()),
                              static_cast<g2s::Index>(t.z())});
  }
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  return g2s::peers::run_peer(argc, argv, "open3d-bpa", reconstruct);
}
