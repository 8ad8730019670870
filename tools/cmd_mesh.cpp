// g2s mesh: read a cloud, mesh it, write the mesh, print a summary and the mesh's defects.
#include <fmt/core.h>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/mesher.hpp"
#include "g2s/stats.hpp"
#include "g2s/surface_check.hpp"

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

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// A one-line progress bar on stderr, redrawn in place; only when stderr is a terminal.
class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}
  void stage(const char* name, double fraction) {
    if (!enabled_) return;
    const int width = 30;
    const int done = static_cast<int>(fraction * width + 0.5);
    fmt::print(stderr, "\r{:<10} [{:<{}}] {:3.0f}%", name, std::string(done, '#'), width,
               fraction * 100);
    std::fflush(stderr);
  }
  void clear() {
    if (enabled_) fmt::print(stderr, "\r{:60}\r", "");
  }

 private:
  bool enabled_;
};

// What the reader left out, on stderr: the input was usable, but not all of it was used.
void print_input_notes(const std::string& input, const ReadReport& report) {
  if (report.non_finite > 0) {
    fmt::print(stderr, "g2s: note: {}: {} points with NaN or Inf coordinates dropped\n", input,
               report.non_finite);
  }
  if (report.ignored_bytes > 0) {
    fmt::print(stderr,
               "g2s: note: {}: {} bytes after the {} declared vertices ignored (the header "
               "declares fewer points than the file holds, or trailing data)\n",
               input, report.ignored_bytes, report.declared);
  }
}

// STL holds 32-bit floats, whose step near 1e7 (georeferenced scans) is a metre: warn when that
// rounding moves vertices by more than a hundredth of the sampling spacing.
void warn_if_stl_rounds(const std::string& output, const PointCloud& cloud, double spacing) {
  double largest = 0.0, worst = 0.0;
  for (const double c : cloud.xyz) {
    largest = std::max(largest, std::abs(c));
    worst = std::max(worst, std::abs(c - static_cast<double>(static_cast<float>(c))));
  }
  if (worst > 0.01 * spacing) {
    fmt::print(stderr,
               "g2s: warning: {}: STL stores 32-bit floats, which round coordinates as large as "
               "{:.6g} by up to {:.3g} (the point spacing is {:.3g}); write .ply to keep them "
               "exactly\n",
               output, largest, worst, spacing);
  }
}

// The mesher works in float around the bounding-box centre, so a cloud far wider than its
// sampling (a stray point at 0, 0, 0 in a georeferenced scan) loses its detail there: warn when
// float's step at the cloud's half-width exceeds a tenth of the point spacing.
void warn_if_local_frame_rounds(const std::string& input, const PointCloud& cloud, double spacing) {
  double half_width = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    double lo = cloud.xyz[axis], hi = lo;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      lo = std::min(lo, cloud.xyz[3 * i + axis]);
      hi = std::max(hi, cloud.xyz[3 * i + axis]);
    }
    half_width = std::max(half_width, 0.5 * (hi - lo));
  }
  const double step = half_width * std::numeric_limits<float>::epsilon();
  if (step > 0.1 * spacing) {
    fmt::print(stderr,
               "g2s: warning: {}: the points spread {:.6g} from their centre, so the mesher's "
               "float coordinates step by {:.3g}, too coarse for the point spacing {:.3g}: points "
               "closer than that may have merged (a stray point far from the rest?)\n",
               input, half_width, step, spacing);
  }
}

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
  if (const std::string why = why_no_surface(cloud); !why.empty()) {
    const std::string dropped =
        read_report.non_finite > 0 ? fmt::format(" ({} points with NaN or Inf coordinates dropped)",
                                                 read_report.non_finite)
                                   : "";
    throw Error(Exit::no_surface, fmt::format("{}: no surface can be formed: {}{}; nothing written",
                                              args.input, why, dropped));
  }
  if (!args.quiet) print_input_notes(args.input, read_report);
  args.options.progress = [&](std::uint64_t used, std::uint64_t total) {
    progress.stage("meshing", static_cast<double>(used) / static_cast<double>(total));
  };
  TileMesh mesh = mesh_cloud(cloud, args.options);
  if (mesh.triangles.empty()) {
    throw Error(Exit::no_surface,
                fmt::format("{}: no surface can be formed: no triangle found among {} points (too "
                            "sparse for --max-radius {}?); nothing written",
                            args.input, cloud.size(), args.options.max_radius));
  }
  if (!args.quiet) warn_if_local_frame_rounds(args.input, cloud, mesh.report.spacing);
  if (!args.quiet && mesh.report.duplicates_merged > 0) {
    fmt::print(stderr,
               "g2s: note: {}: {} duplicate points merged (equal in the mesher's float "
               "coordinates)\n",
               args.input, mesh.report.duplicates_merged);
  }
  const MeshFormat format = mesh_format_for(args.output, args.ascii);
  if (!args.quiet && format != MeshFormat::ply_binary) {
    warn_if_stl_rounds(args.output, cloud, mesh.report.spacing);
  }
  progress.stage("writing", 1);
  write_mesh(args.output, cloud.xyz, mesh.triangles, format);
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
        "{{\"input\":\"{}\",\"output\":\"{}\",\"points\":{},\"non_finite\":{},\"ignored_bytes\":{},"
        "\"duplicates_merged\":{},\"spacing\":{},\"seeds\":{},\"triangles\":{},"
        "\"triangles_removed\":{},\"seconds\":{:.3f},\"seconds_grid\":{:.3f},"
        "\"seconds_grow\":{:.3f},\"seconds_cleanup\":{:.3f},\"ktriangles_per_second\":{:.1f},"
        "\"peak_rss_mb\":{:.1f}",
        args.input, args.output, r.points, read_report.non_finite, read_report.ignored_bytes,
        r.duplicates_merged, r.spacing, r.seeds, r.triangles_grown - r.triangles_removed,
        r.triangles_removed, seconds, r.seconds_grid, r.seconds_grow, r.seconds_cleanup, ktps,
        peak_rss_mb());
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
      "mesh",
      "Reconstruct a triangle mesh from a point cloud (PLY, XYZ/PTS) with G2S.\n"
      "NaN/Inf points are dropped and exact duplicates merged (a note says how many).\n"
      "Exit 3 for a missing or malformed file; exit 5, with nothing written, when the points\n"
      "cannot form a surface: none usable, all the same point, only two distinct points, all\n"
      "on one straight line, or too sparse for any triangle. Flat (coplanar) clouds mesh.");
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
