// g2s mesh: the whole pipeline in one process. The cloud is cut into a tile store (a temporary
// beside the output, or --keep-store), the tiles are grown in parallel, the seams stitched, and
// the mesh written with a summary of its defects. `g2s tile`, `g2s grow` and `g2s stitch` run the
// same stages as separate processes and give the same bytes.
#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>

#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/tile_store.hpp"
#include "mesh_output.hpp"
#include "progress.hpp"

namespace g2s::cli {
namespace {

struct MeshArgs {
  std::string input;
  OutputArgs out;
  int threads = 0;
  std::uint64_t memory = 0;       // 0: default_memory_budget()
  std::uint64_t tile_points = 0;  // 0: from the memory plan
  std::string keep_store;
  bool compress = false;
  PipelineOptions options;
};

// A kept store is reused when it is newer than the input (a re-run after an interruption, or
// with other mesh options); anything else re-tiles.
bool reusable(const std::filesystem::path& store, const std::filesystem::path& input) {
  std::error_code error;
  const auto store_time = std::filesystem::last_write_time(store, error);
  if (error) return false;
  const auto input_time = std::filesystem::last_write_time(input, error);
  return !error && store_time >= input_time;
}

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

// Each tile is meshed in float around its centre, so a tile far wider than its sampling (a
// stray point far from a georeferenced scan stretches its tile) loses detail: warn when float's
// step at the tile's half-width exceeds a tenth of its point spacing.
void warn_if_local_frame_rounds(const std::string& input, const TileStore& store) {
  for (const TileInfo& t : store.tiles()) {
    double half_width = 0.0;
    for (int a = 0; a < 3; ++a)
      half_width = std::max(half_width, 0.5 * (t.box.hi[a] - t.box.lo[a]));
    const double step = half_width * std::numeric_limits<float>::epsilon();
    if (t.points > 1 && step > 0.1 * t.spacing) {
      fmt::print(stderr,
                 "g2s: warning: {}: the points of a tile spread {:.6g} from its centre, so the "
                 "mesher's float coordinates step by {:.3g}, too coarse for the point spacing "
                 "{:.3g}: points closer than that may have merged (a stray point far from the "
                 "rest?)\n",
                 input, half_width, step, t.spacing);
      return;
    }
  }
}

void run_mesh(MeshArgs& args) {
  Progress progress(!args.out.quiet && !args.out.json);
  RunFacts run{args.input, 0, 0, std::chrono::steady_clock::now(), {}};
  std::unique_ptr<TemporaryPath> temporary;
  std::filesystem::path store_path = args.keep_store;
  if (store_path.empty()) {
    const std::filesystem::path output(args.out.output);
    temporary = std::make_unique<TemporaryPath>(
        output.parent_path() /
        fmt::format(".{}.store-{}", output.filename().string(), static_cast<long>(getpid())));
    store_path = temporary->path();
  }
  const std::uint64_t budget = args.memory > 0 ? args.memory : default_memory_budget();
  const MemoryPlan plan = plan_memory(budget, args.threads);
  args.out.memory = budget;
  ReadReport read;
  if (temporary || !reusable(store_path, args.input)) {
    TileStoreOptions tiling;
    tiling.tile_points = args.tile_points > 0 ? args.tile_points : plan.tile_points;
    if (args.tile_points == 0) tiling.min_tiles = plan.min_tiles;
    tiling.round_points = std::max(plan.round_points, tiling.tile_points);
    tiling.compress = args.compress;
    tiling.progress = [&](std::uint64_t done, std::uint64_t total) {
      progress.stage("tiling", total ? static_cast<double>(done) / static_cast<double>(total) : 1);
    };
    const auto start = std::chrono::steady_clock::now();
    const double cpu = cpu_seconds();
    read = build_tile_store(args.input, store_path, tiling).read;
    run.tile = {std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                cpu_seconds() - cpu};
  }
  const TileStore store(store_path);
  if (read.format.empty()) read = store.input_report();
  run.non_finite = read.non_finite;
  run.ignored_bytes = read.ignored_bytes;
  if (!args.out.quiet) print_input_notes(args.input, read);
  args.options.threads = args.threads;
  args.options.tiles_in_flight = plan.tiles_in_flight;
  args.options.progress = [&](std::uint64_t done, std::uint64_t total) {
    progress.stage("meshing", static_cast<double>(done) / static_cast<double>(total));
  };
  write_and_report(
      store,
      [&](MeshSink& sink) {
        const PipelineSummary summary = mesh_tiles(store, args.options, sink);
        progress.clear();
        if (!args.out.quiet && summary.triangles > 0) {
          warn_if_local_frame_rounds(args.input, store);
          if (summary.report.duplicates_merged > 0) {
            fmt::print(stderr,
                       "g2s: note: {}: {} duplicate points merged (equal in the mesher's float "
                       "coordinates)\n",
                       args.input, summary.report.duplicates_merged);
          }
        }
        return summary;
      },
      args.out, run);
}

}  // namespace

void add_mesh_options(CLI::App& cmd, PipelineOptions& options) {
  cmd.add_option("--radius-steps", options.mesh.radius_steps,
                 "Search radius levels, in edge lengths, increasing (default 1 1.5 2 3); "
                 "more levels close more gaps in sparse regions, at some cost in speed")
      ->expected(1, 16);
  cmd.add_option("--flatness-levels", options.mesh.flatness_levels,
                 "Flatness levels m of the priority queue (default 4); more levels mesh flat "
                 "regions first more strictly")
      ->check(CLI::Range(1, 64));
  cmd.add_option("--max-fold", options.mesh.max_fold_deg,
                 "Largest angle in degrees between neighbouring triangle normals (default 135); "
                 "lower it on noisy scans to avoid folds, raise it for very sharp edges")
      ->check(CLI::Range(10.0, 179.0));
  cmd.add_option("--max-radius", options.mesh.max_radius,
                 "Largest search ball, in sampling spacings (default 6); larger bridges wider "
                 "gaps and scan borders, at a cost in speed on sparse or noisy regions")
      ->check(CLI::Range(1.0, 1000.0));
  cmd.add_flag(
      "--keep-gaps", [&options](std::int64_t) { options.mesh.close_gaps = false; },
      "Leave gaps of three open edges open after growth (the paper's G2S alone)");
  cmd.add_flag(
      "--no-orient", [&options](std::int64_t) { options.mesh.orient = false; },
      "Keep each component's seed orientation instead of facing closed ones outward");
}

void add_output_options(CLI::App& cmd, OutputArgs& out) {
  cmd.add_option("-o,--output", out.output,
                 "Mesh to write: .stl (binary; --ascii for ASCII) or .ply (indexed binary)")
      ->required();
  cmd.add_flag("--ascii", out.ascii, "Write ASCII STL instead of binary");
  cmd.add_flag("-q,--quiet", out.quiet, "Print nothing on success");
  cmd.add_flag("--json", out.json, "Print the summary as one JSON object on stdout");
  cmd.add_flag("--no-stats", out.no_stats, "Skip measuring the mesh's defects");
}

void add_mesh_command(CLI::App& app) {
  auto args = std::make_shared<MeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Reconstruct a triangle mesh from a point cloud (PLY, XYZ/PTS) with G2S");
  cmd->add_option("input", args->input, "Point cloud: PLY (ascii/binary) or text XYZ/PTS")
      ->required();
  add_output_options(*cmd, args->out);
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--memory", args->memory,
                  "Memory budget, e.g. 512M or 4G (default: half the machine's RAM): sets the "
                  "tile size and the tiles in flight; the peak resident memory stays below it")
      ->transform(CLI::AsSizeValue(false));
  cmd->add_option("--tile-points", args->tile_points,
                  "Largest number of points in a tile (default: a quarter of the cloud, at "
                  "least 16384, at most 1048576 and what --memory holds): the cloud is cut into "
                  "tiles grown in parallel and stitched at the seams")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--keep-store", args->keep_store,
                  "Keep the tile store at this path (reused by the next run while it is newer "
                  "than the input) instead of a temporary beside the output");
  cmd->add_flag("--compress", args->compress, "zstd-compress the tile store");
  add_mesh_options(*cmd, args->options);
  cmd->callback([args] { run_mesh(*args); });
}

}  // namespace g2s::cli
