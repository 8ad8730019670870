// Peer driver: PCL's GreedyProjectionTriangulation (Marton, Rusu & Beetz, 2009) as PCL's tutorial
// "Fast triangulation of unordered point clouds" (greedy_projection.cpp) runs it: normals from
// NormalEstimation over the 20 nearest neighbours, then mu 2.5, 100 nearest neighbours, 45°
// surface angle, 10°/120° triangle angles, no normal consistency. The tutorial's search radius
// (0.025 m for its bunny) is an absolute length; here it is a multiple of the cloud's mean
// nearest-neighbour spacing (kSearchRadiusSpacings, why: bench/peers/README.md). Usage and
// output: peer_driver.hpp.
#include <pcl/common/io.h>
#include <pcl/features/normal_3d.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/surface/gp3.h>

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "peer_driver.hpp"

namespace {

constexpr double kSearchRadiusSpacings = 2.0;  // the tutorial's 0.025 m over its bunny's spacing

// Mean distance from each point to its nearest other point.
double mean_spacing(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                    pcl::search::KdTree<pcl::PointXYZ>& tree) {
  std::vector<int> index(2);
  std::vector<float> distance2(2);
  double sum = 0;
  std::size_t counted = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (tree.nearestKSearch((*cloud)[i], 2, index, distance2) == 2) {
      sum += std::sqrt(static_cast<double>(distance2[1]));
      ++counted;
    }
  }
  return counted ? sum / static_cast<double>(counted) : 0.0;
}

g2s::IndexedMesh reconstruct(g2s::PointCloud& input) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->resize(input.size());
  for (std::size_t i = 0; i < input.size(); ++i) {
    (*cloud)[i] = pcl::PointXYZ(static_cast<float>(input.xyz[3 * i]),
                                static_cast<float>(input.xyz[3 * i + 1]),
                                static_cast<float>(input.xyz[3 * i + 2]));
  }

  // Normal estimation, as in the tutorial.
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(cloud);
  estimation.setInputCloud(cloud);
  estimation.setSearchMethod(tree);
  estimation.setKSearch(20);
  estimation.compute(*normals);
  pcl::PointCloud<pcl::PointNormal>::Ptr with_normals(new pcl::PointCloud<pcl::PointNormal>);
  pcl::concatenateFields(*cloud, *normals, *with_normals);
  const double spacing = mean_spacing(cloud, *tree);

  pcl::search::KdTree<pcl::PointNormal>::Ptr tree2(new pcl::search::KdTree<pcl::PointNormal>);
  tree2->setInputCloud(with_normals);
  pcl::GreedyProjectionTriangulation<pcl::PointNormal> gp3;
  gp3.setSearchRadius(kSearchRadiusSpacings * spacing);
  gp3.setMu(2.5);
  gp3.setMaximumNearestNeighbors(100);
  gp3.setMaximumSurfaceAngle(std::numbers::pi / 4);
  gp3.setMinimumAngle(std::numbers::pi / 18);
  gp3.setMaximumAngle(2 * std::numbers::pi / 3);
  gp3.setNormalConsistency(false);
  gp3.setInputCloud(with_normals);
  gp3.setSearchMethod(tree2);
  std::vector<pcl::Vertices> polygons;
  gp3.reconstruct(polygons);

  g2s::IndexedMesh mesh;
  mesh.triangles.reserve(polygons.size());
  for (const pcl::Vertices& p : polygons) {  // indices into the input cloud
    if (p.vertices.size() != 3) continue;
    mesh.triangles.push_back({static_cast<g2s::Index>(p.vertices[0]),
                              static_cast<g2s::Index>(p.vertices[1]),
                              static_cast<g2s::Index>(p.vertices[2])});
  }
  mesh.xyz = std::move(input.xyz);
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  return g2s::peers::run_peer(argc, argv, "pcl-gp3", reconstruct);
}
