// g2s mesh: the whole pipeline in one process. The cloud is cut into a tile store (a temporary
// beside the output, or --keep-store), the tiles are grown in parallel, the seams stitched, and
// the mesh written with a summary of its defects. `g2s tile`, `g2s grow` and `g2s stitch` run the
// same stages as separate processes and give the same bytes.
#include <fmt/core.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>
#include <optional>

#include "cli_checks.hpp"
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

// A kept store is reused only when it was made from this input (path, size, time, content
// fingerprint) with this tiling; an older or other store is rebuilt, with a note. A file there
// that is no tile store at all is refused rather than overwritten (kept_store_matches).
bool reusable(const std::filesystem::path& store, const std::filesystem::path& input,
              std::uint64_t tile_points, bool quiet) {
  std::string why;
  try {
    if (kept_store_matches(store, input, tile_points, why)) return true;
  } catch (const Error& e) {
    if (e.code() != Exit::usage) throw;
    throw Error(e.code(), fmt::format("--keep-store {}", e.what()));
  }
  if (!quiet && !why.empty()) {
    fmt::print(stderr, "g2s: note: --keep-store {} {}; tiling again\n", store.string(), why);
  }
  return false;
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

void run_mesh(MeshArgs& args) {
  Progress progress(!args.out.quiet && !args.out.json);
  RunFacts run{args.input, 0, 0, std::chrono::steady_clock::now(), {}, {}, {}};
  refuse_same_file({args.input}, args.out.output, "-o");
  checked_mesh_format(args.out.output, args.out.ascii);
  check_radius_steps(args.options.mesh.radius_steps);
  if (!args.keep_store.empty()) {
    refuse_same_file({args.input}, args.keep_store, "--keep-store");
    refuse_same_file({args.keep_store}, args.out.output, "-o");
  }
  std::unique_ptr<TemporaryPath> temporary;
  std::filesystem::path store_path = args.keep_store;
  if (store_path.empty()) {
    const std::filesystem::path output(args.out.output);
    temporary = std::make_unique<TemporaryPath>(
        hidden_beside(output, fmt::format("store-{}", static_cast<long>(getpid()))));
    store_path = temporary->path();
    run.output_written = [&temporary] { temporary.reset(); };
    run.temporary_store = store_path.string();
  }
  const std::uint64_t budget = args.memory > 0 ? args.memory : default_memory_budget();
  // Refuses a budget too small for any tile before anything is read.
  const std::uint64_t planned_tile =
      args.tile_points > 0 ? args.tile_points : plan_memory(budget, args.threads).tile_points;
  fit_heap_to_budget(budget);
  args.out.memory = budget;
  args.options.threads = args.threads;
  try {
    TileStoreOptions tiling;
    tiling.tile_points = args.tile_points;
    tiling.compress = args.compress;
    tiling.progress = [&](std::uint64_t done, std::uint64_t total) {
      progress.stage("tiling", total ? static_cast<double>(done) / static_cast<double>(total) : 1);
    };
    // A kept store is reused only as the first cut for this plan: a store cut again for its
    // band records its own tile, so the next run starts over from the first cut, as a fresh
    // one does, and gives the same bytes.
    const bool first_cut_made =
        !temporary && reusable(store_path, args.input, planned_tile, args.out.quiet);
    const auto start = std::chrono::steady_clock::now();
    const double cpu = cpu_seconds();
    const BudgetTiling tiled =
        tile_for_budget(args.input, store_path, budget, args.options, tiling, first_cut_made);
    if (tiled.cuts > 0) {
      run.tile = {std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                  cpu_seconds() - cpu};
    }
    if (tiled.band_needs > 0 && !args.out.quiet) {
      fmt::print(stderr,
                 "g2s: warning: {}: --memory {} MB cannot hold the band of open seams (about {} "
                 "points held at once; {} MB would, with the smallest tiles): the peak may "
                 "exceed it\n",
                 args.input, budget >> 20, tiled.live_points, (tiled.band_needs >> 20) + 1);
    }
    ReadReport read = tiled.read;
    const TileStore store(store_path);
    if (read.format.empty()) read = store.input_report();
    run.non_finite = read.non_finite;
    run.ignored_bytes = read.ignored_bytes;
    if (!args.out.quiet) print_input_notes(args.input, read);
    args.options.tiles_in_flight = tiled.plan.tiles_in_flight;
    args.options.progress = [&](std::uint64_t done, std::uint64_t total) {
      progress.stage("meshing", static_cast<double>(done) / static_cast<double>(total));
    };
    write_and_report(
        store,
        [&](MeshSink& sink) {
          const PipelineSummary summary = mesh_tiles(store, args.options, sink);
          progress.clear();
          if (!args.out.quiet && summary.triangles > 0) {
            if (summary.report.duplicates_merged > 0 && store.twin_distance() > 0) {
              fmt::print(stderr,
                         "g2s: note: {}: {} duplicate points and near-copies merged (most points "
                         "have a near-copy: points within {:.3g} of each other are taken as "
                         "one)\n",
                         args.input, summary.report.duplicates_merged, store.twin_distance());
            } else if (summary.report.duplicates_merged > 0) {
              fmt::print(stderr,
                         "g2s: note: {}: {} duplicate points merged (equal in the mesher's "
                         "float coordinates)\n",
                         args.input, summary.report.duplicates_merged);
            }
          }
          return summary;
        },
        args.out, run);
  } catch (const Error& e) {
    // The temporary store's name means nothing to the user: name what they typed.
    if (!temporary) throw;
    std::string message = e.what();
    const std::string hidden = temporary->path().string();
    for (std::size_t at; (at = message.find(hidden)) != std::string::npos;) {
      message.replace(at, hidden.size(),
                      fmt::format("the temporary tile store for {}", args.out.output));
    }
    throw Error(e.code(), message);
  }
}

}  // namespace

void add_mesh_options(CLI::App& cmd, PipelineOptions& options) {
  cmd.add_option("--radius-steps", options.mesh.radius_steps,
                 "Search radius levels, in edge lengths, increasing (default 1 1.5 2 3); "
                 "more levels close more gaps in sparse regions, at some cost in speed")
      ->expected(1, 16)
      ->check(finite_range(0.01, 1000.0));
  cmd.add_option("--flatness-levels", options.mesh.flatness_levels,
                 "Flatness levels m of the priority queue (default 4); more levels mesh flat "
                 "regions first more strictly")
      ->check(count_range(1, 64));
  cmd.add_option("--max-fold", options.mesh.max_fold_deg,
                 "Largest angle in degrees between neighbouring triangle normals (default 135); "
                 "lower it on noisy scans to avoid folds, raise it for very sharp edges")
      ->check(finite_range(10.0, 179.0));
  cmd.add_option("--max-radius", options.mesh.max_radius,
                 "Largest search ball, in sampling spacings (default 6); larger bridges wider "
                 "gaps and scan borders, at a cost in speed on sparse or noisy regions")
      ->check(finite_range(1.0, 1000.0));
  cmd.add_flag(
      "--keep-gaps", [&options](std::int64_t) { options.mesh.close_gaps = false; },
      "Leave gaps of three open edges open after growth (the paper's G2S alone)");
  cmd.add_option("--max-hole-edges", options.mesh.max_hole_edges,
                 "Once grown, close holes whose boundary loop has at most this many edges, with "
                 "triangles over the loop's own points (default 30, at most 100; 0 leaves every "
                 "hole)")
      ->check(count_range(0, MeshOptions::kMaxHoleEdges));
  cmd.add_option("--max-hole-rings", options.mesh.max_hole_rings,
                 "A hole that cannot be closed over its own points may be widened by up to this "
                 "many rings of triangles and closed in their place, leaving out only points "
                 "within 3 spacings of the surface, and scraps of surface that close to the rest "
                 "are removed (default 3, at most 10; 0 leaves out no point)")
      ->check(count_range(0, MeshOptions::kMaxHoleRings));
  cmd.add_flag(
      "--no-orient", [&options](std::int64_t) { options.mesh.orient = false; },
      "Keep each component's seed orientation instead of facing closed ones outward");
}

void add_output_options(CLI::App& cmd, OutputArgs& out) {
  cmd.add_option("-o,--output", out.output,
                 "Mesh to write: .stl (binary; --ascii for ASCII) or .ply (indexed binary); "
                 "other extensions are refused")
      ->required();
  cmd.add_flag("--ascii", out.ascii, "Write ASCII STL instead of binary");
  cmd.add_flag("-q,--quiet", out.quiet, "Print nothing on success");
  cmd.add_flag("--json", out.json, "Print the summary as one JSON object on stdout");
  cmd.add_flag("--no-stats", out.no_stats, "Skip measuring the mesh's defects");
}

void add_mesh_command(CLI::App& app) {
  auto args = std::make_shared<MeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Reconstruct a triangle mesh from a point cloud (PLY, LAS, XYZ/PTS) with G2S");
  cmd->add_option("input", args->input, "Point cloud: PLY (ascii/binary), LAS or text XYZ/PTS")
      ->required();
  add_output_options(*cmd, args->out);
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(count_range(0, kMostThreads));
  cmd->add_option(
         "--memory", args->memory,
         "Memory budget, e.g. 512M or 4G (default: half the machine's RAM): sets the "
         "tile size and the tiles in flight, with room for the band of open seams predicted "
         "from the tiles; the peak resident memory stays below it, or a warning says that the "
         "band cannot fit")
      ->transform(byte_size());
  cmd->add_option("--tile-points", args->tile_points,
                  "Largest number of points in a tile (default: a quarter of the cloud, at "
                  "least 16384, at most 1048576 and what --memory holds; at least 500): the "
                  "cloud is cut into tiles grown in parallel and stitched at the seams")
      ->check(count_range(kFewestTilePoints, 0xFFFFFFFF));
  cmd->add_option("--keep-store", args->keep_store,
                  "Keep the tile store at this path instead of a temporary beside the output; "
                  "the next run reuses it if it was made from the same input (path, size, "
                  "time, content) with the same tiling (--tile-points, or the first cut --memory "
                  "plans), else tiles again");
  cmd->add_flag("--compress", args->compress, "zstd-compress the tile store");
  add_mesh_options(*cmd, args->options);
  // Every stage in one arena of --threads threads: the tiling and the output keep to the count
  // too (a shared node's allocation), and the pipeline needs no arena of its own (mesh_tiles).
  // More threads than cores are allowed as asked: TBB would otherwise keep to the cores and warn.
  cmd->callback([args] {
    std::optional<tbb::global_control> allow;
    if (args->threads > tbb::info::default_concurrency()) {
      allow.emplace(tbb::global_control::max_allowed_parallelism,
                    static_cast<std::size_t>(args->threads));
    }
    tbb::task_arena(args->threads > 0 ? args->threads : tbb::task_arena::automatic).execute([&] {
      run_mesh(*args);
    });
  });
}

}  // namespace g2s::cli
