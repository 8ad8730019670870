// `g2s stats MESH [--points CLOUD] [--json] [--largest-component]`: measures a mesh's defects
// (docs/algorithm.md §9, "Measuring a mesh"), or those of its largest piece, and prints them as
// aligned text or one JSON object. Defects are data: exit 0 whenever the mesh could be read and
// measured; unreadable input exits 3 through g2s::Error.
#include <fmt/core.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "g2s/io.hpp"
#include "g2s/stats.hpp"

namespace g2s::cli {
namespace {

struct StatsArgs {
  std::string mesh;
  std::string points;
  bool json = false;
  bool largest = false;
};

void run_stats(const StatsArgs& args) {
  IndexedMesh mesh = read_mesh(args.mesh);
  if (args.largest) mesh = largest_component(mesh);
  MeshStats stats;
  if (args.points.empty()) {
    stats = compute_stats(mesh);
  } else {
    const PointCloud cloud = read_points(args.points);
    stats = compute_stats(mesh, &cloud);
  }
  if (args.json) {
    fmt::print("{}\n", stats_to_json(stats));
  } else {
    fmt::print("{}", stats_to_text(stats));
  }
  std::fflush(stdout);
}

}  // namespace

void add_stats_command(CLI::App& app) {
  auto args = std::make_shared<StatsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stats",
      "Measure a triangle mesh (STL or PLY): triangles, vertices, degenerate and duplicate\n"
      "triangles, non-manifold edges and vertices, boundary edges, holes, orientation\n"
      "conflicts, components, crossing triangle pairs (exact); with --points, the share of the\n"
      "cloud's points used as vertices and the distances of the others to the mesh.\n"
      "Exit 0 whenever the mesh was measured, whatever its defects.");
  cmd->add_option("MESH", args->mesh, "Mesh to measure (.stl binary or ASCII, .ply)")->required();
  cmd->add_option(
      "--points", args->points,
      "Input cloud (PLY, LAS, XYZ): adds its coverage (compared at float precision when every\n"
      "vertex is a float, as in STL, else exactly) and the distances of its other points to\n"
      "the mesh, in sampling spacings");
  cmd->add_flag("--json", args->json, "Print one JSON object instead of text");
  cmd->add_flag("--largest-component", args->largest,
                "Measure only the largest connected piece (most triangles), e.g. a scan's own\n"
                "surface without stray patches; coverage still counts every given point");
  cmd->callback([args] { run_stats(*args); });
}

}  // namespace g2s::cli
