// g2s mesh: read a cloud, mesh it, write the mesh, print a summary and the mesh's defects.
#include <fmt/core.h>
#include <tbb/global_control.h>

#include <chrono>

#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/mesher.hpp"
#include "g2s/stats.hpp"
#include "progress.hpp"

namespace g2s::cli {
namespace {

struct MeshArgs {
  std::string input;
  std::string output;
  int threads = 0;
  bool ascii = false;
  bool quiet = false;
  bool json = false;
  bool no_stats = false;
  MeshOptions options;
};

void run_mesh(MeshArgs& args) {
  std::unique_ptr<tbb::global_control> threads;
  if (args.threads > 0) {
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(args.threads));
  }
  Progress progress(!args.quiet && !args.json);
  const auto t0 = std::chrono::steady_clock::now();
  progress.stage("reading", 0);
  ReadReport read_report;
  PointCloud cloud = read_points(args.input, &read_report);
  if (cloud.size() == 0) {
    throw Error(Exit::bad_input,
                fmt::format("{}: no usable points ({} read, {} non-finite)", args.input,
                            read_report.points + read_report.non_finite, read_report.non_finite));
  }
  args.options.progress = [&](std::uint64_t used, std::uint64_t total) {
    progress.stage("meshing", static_cast<double>(used) / static_cast<double>(total));
  };
  TileMesh mesh = mesh_cloud(cloud, args.options);
  if (mesh.triangles.empty()) {
    throw Error(Exit::bad_input,
                fmt::format("{}: no triangle could be formed from {} points (too few, collinear "
                            "or too sparse); nothing written",
                            args.input, cloud.size()));
  }
  progress.stage("writing", 1);
  write_mesh(args.output, cloud.xyz, mesh.triangles, mesh_format_for(args.output, args.ascii));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress.clear();

  const MeshReport& r = mesh.report;
  const double ktps = static_cast<double>(mesh.triangles.size()) / seconds / 1000.0;
  MeshStats stats;
  if (!args.no_stats) {
    IndexedMesh indexed{std::move(cloud.xyz), std::move(mesh.triangles)};
    stats = compute_stats(indexed);
  }
  if (args.json) {
    fmt::print(
        "{{\"input\":\"{}\",\"output\":\"{}\",\"points\":{},\"non_finite\":{},"
        "\"duplicates_merged\":{},\"spacing\":{},\"seeds\":{},\"triangles\":{},"
        "\"triangles_removed\":{},\"seconds\":{:.3f},\"seconds_grid\":{:.3f},"
        "\"seconds_grow\":{:.3f},\"seconds_cleanup\":{:.3f},\"ktriangles_per_second\":{:.1f},"
        "\"peak_rss_mb\":{:.1f}",
        args.input, args.output, r.points, read_report.non_finite, r.duplicates_merged, r.spacing,
        r.seeds, r.triangles_grown - r.triangles_removed, r.triangles_removed, seconds,
        r.seconds_grid, r.seconds_grow, r.seconds_cleanup, ktps, peak_rss_mb());
    if (!args.no_stats) fmt::print(",\"stats\":{}", stats_to_json(stats));
    fmt::print("}}\n");
    return;
  }
  if (args.quiet) return;
  fmt::print(
      stderr, "{}: {} points -> {} triangles in {:.2f} s ({:.0f} k triangles/s), peak {:.0f} MB",
      args.output, r.points, r.triangles_grown - r.triangles_removed, seconds, ktps, peak_rss_mb());
  if (!args.no_stats) {
    fmt::print(stderr,
               "; non-manifold edges {}, non-manifold vertices {}, orientation conflicts {}, "
               "boundary edges {}, holes {}",
               stats.non_manifold_edges, stats.non_manifold_vertices, stats.orientation_conflicts,
               stats.boundary_edges, stats.holes);
  }
  fmt::print(stderr, "\n");
}

}  // namespace

void add_mesh_command(CLI::App& app) {
  auto args = std::make_shared<MeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Reconstruct a triangle mesh from a point cloud (PLY, XYZ/PTS) with G2S");
  cmd->add_option("input", args->input, "Point cloud: PLY (ascii/binary) or text XYZ/PTS")
      ->required();
  cmd->add_option("-o,--output", args->output,
                  "Mesh to write: .stl (binary; --ascii for ASCII) or .ply (indexed binary)")
      ->required();
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--ascii", args->ascii, "Write ASCII STL instead of binary");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
  cmd->add_flag("--json", args->json, "Print the summary as one JSON object on stdout");
  cmd->add_flag("--no-stats", args->no_stats, "Skip measuring the mesh's defects");
  cmd->add_option("--radius-steps", args->options.radius_steps,
                  "Search radius levels, in edge lengths, increasing (default 1 1.5 2 3); "
                  "more levels close more gaps in sparse regions, at some cost in speed")
      ->expected(1, 16);
  cmd->add_option("--flatness-levels", args->options.flatness_levels,
                  "Flatness levels m of the priority queue (default 4); more levels mesh flat "
                  "regions first more strictly")
      ->check(CLI::Range(1, 64));
  cmd->add_option("--max-fold", args->options.max_fold_deg,
                  "Largest angle in degrees between neighbouring triangle normals (default 135); "
                  "lower it on noisy scans to avoid folds, raise it for very sharp edges")
      ->check(CLI::Range(10.0, 179.0));
  cmd->add_option("--max-radius", args->options.max_radius,
                  "Largest search ball, in sampling spacings (default 6); larger bridges wider "
                  "gaps and scan borders, at a cost in speed on sparse or noisy regions")
      ->check(CLI::Range(1.0, 1000.0));
  cmd->add_flag(
      "--no-orient", [args](std::int64_t) { args->options.orient = false; },
      "Keep each component's seed orientation instead of facing closed ones outward");
  cmd->callback([args] { run_mesh(*args); });
}

}  // namespace g2s::cli
