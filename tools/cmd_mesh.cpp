// g2s mesh: the whole pipeline in one process. The cloud is cut into a tile store (a temporary
// beside the output, or --keep-store), the tiles are grown in parallel, the seams stitched, and
// the mesh written with a summary of its defects. `g2s tile`, `g2s grow` and `g2s stitch` run the
// same stages as separate processes and give the same bytes.
#include <fmt/core.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>

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
  std::uint64_t tile_points = std::uint64_t{1} << 20;
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

void run_mesh(MeshArgs& args) {
  Progress progress(!args.out.quiet && !args.out.json);
  const RunFacts facts{args.input, 0, std::chrono::steady_clock::now()};
  std::unique_ptr<TemporaryPath> temporary;
  std::filesystem::path store_path = args.keep_store;
  if (store_path.empty()) {
    const std::filesystem::path output(args.out.output);
    temporary = std::make_unique<TemporaryPath>(
        output.parent_path() /
        fmt::format(".{}.store-{}", output.filename().string(), static_cast<long>(getpid())));
    store_path = temporary->path();
  }
  RunFacts run = facts;
  if (temporary || !reusable(store_path, args.input)) {
    TileStoreOptions tiling;
    tiling.tile_points = args.tile_points;
    tiling.compress = args.compress;
    tiling.progress = [&](std::uint64_t done, std::uint64_t total) {
      progress.stage("tiling", total ? static_cast<double>(done) / static_cast<double>(total) : 1);
    };
    build_tile_store(args.input, store_path, tiling);
  }
  const TileStore store(store_path);
  run.non_finite = store.input_report().non_finite;
  if (store.point_count() == 0) {
    throw Error(Exit::bad_input,
                fmt::format("{}: no usable points ({} non-finite)", args.input, run.non_finite));
  }
  args.options.threads = args.threads;
  args.options.progress = [&](std::uint64_t done, std::uint64_t total) {
    progress.stage("meshing", static_cast<double>(done) / static_cast<double>(total));
  };
  PipelineMesh mesh = mesh_tiles(store, args.options);
  progress.stage("writing", 1);
  progress.clear();
  write_and_report(mesh, args.out, run);
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
  cmd->add_option("--tile-points", args->tile_points,
                  "Largest number of points in a tile (default 1048576): the cloud is cut into "
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
