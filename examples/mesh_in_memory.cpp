// In-memory meshing with the g2s library: read a point cloud (PLY, LAS or XYZ), mesh it whole
// with mesh_cloud, measure the mesh's defects and write it.
//   mesh_in_memory CLOUD OUT.ply
#include <cstdio>
#include <g2s/error.hpp>
#include <g2s/io.hpp>
#include <g2s/pipeline.hpp>
#include <g2s/stats.hpp>
#include <utility>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s CLOUD OUT.ply\n", argv[0]);
    return 2;
  }
  try {
    const g2s::PointCloud cloud = g2s::read_points(argv[1]);
    g2s::PipelineOptions options;  // the CLI's defaults; options.mesh holds the mesher's
    g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud, options);
    // The triangles index into cloud.xyz: the mesh interpolates the points.
    g2s::write_mesh(argv[2], cloud.xyz, mesh.triangles, g2s::mesh_format_for(argv[2], false));
    const g2s::MeshStats stats = g2s::compute_stats({cloud.xyz, std::move(mesh.triangles)}, &cloud);
    std::printf("%s: %zu points -> %llu triangles, %llu non-manifold edges, %llu boundary edges\n",
                argv[2], cloud.size(), static_cast<unsigned long long>(stats.triangles),
                static_cast<unsigned long long>(stats.non_manifold_edges),
                static_cast<unsigned long long>(stats.boundary_edges));
    return stats.triangles > 0 ? 0 : 5;
  } catch (const g2s::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return static_cast<int>(e.code());
  }
}
