// Out-of-core meshing with the g2s library, as `g2s mesh` does it: the cloud is cut into a tile
// store on disk in bounded memory, the tiles are grown in parallel and stitched, and the mesh is
// streamed into the output file as the stitcher finishes it.
//   mesh_out_of_core CLOUD OUT.ply [TILE-POINTS]
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <g2s/error.hpp>
#include <g2s/io.hpp>
#include <g2s/pipeline.hpp>
#include <g2s/tile_store.hpp>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: %s CLOUD OUT.ply [TILE-POINTS]\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path output = argv[2];
    // The tile store lives beside the output while the run needs it.
    std::string store_name = ".";
    store_name += output.filename().string();
    store_name += ".store";
    const g2s::TemporaryPath store_path(output.parent_path() / store_name);
    const g2s::MemoryPlan plan = g2s::plan_memory(std::uint64_t{512} << 20, 0);  // a 512 MB budget
    g2s::TileStoreOptions tiling;
    tiling.tile_points = argc == 4 ? std::strtoull(argv[3], nullptr, 10) : plan.tile_points;
    tiling.round_points = std::max(plan.round_points, tiling.tile_points);
    const g2s::TileStoreReport tiled = g2s::build_tile_store(argv[1], store_path.path(), tiling);
    const g2s::TileStore store(store_path.path());

    g2s::PipelineOptions options;  // options.mesh holds the mesher's options
    options.tiles_in_flight = plan.tiles_in_flight;
    g2s::MeshStreamWriter writer(output, g2s::mesh_format_for(output, false));
    const g2s::PipelineSummary summary = g2s::mesh_tiles(store, options, writer);
    std::printf(
        "%s: %llu points (%s) in %llu tiles -> %llu triangles, %llu stitched at the seams\n",
        argv[2], static_cast<unsigned long long>(tiled.read.points), tiled.read.format.c_str(),
        static_cast<unsigned long long>(summary.tiles),
        static_cast<unsigned long long>(summary.triangles),
        static_cast<unsigned long long>(summary.triangles_stitched));
    return summary.triangles > 0 ? 0 : 5;
  } catch (const g2s::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return static_cast<int>(e.code());
  }
}
