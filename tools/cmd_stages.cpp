// `g2s grow` and `g2s stitch`: the pipeline's stages as separate processes, so a scheduler
// (GNU parallel, a Slurm job array; docs/pipeline.md) can grow different tiles in different
// processes or on different machines sharing the store. Each grown tile is a file in the
// store's growth folder; growing again skips tiles whose file is already there and sound, so an
// interrupted run resumes.
#include <fmt/core.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string_view>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/tile_store.hpp"
#include "mesh_output.hpp"
#include "progress.hpp"

namespace g2s::cli {
namespace {

struct GrowArgs {
  std::string store;
  std::string grown;  // default: STORE.grown
  std::string tiles;  // "A-B", "A" or empty for all
  int threads = 0;
  bool quiet = false;
  PipelineOptions options;
};

struct StitchArgs {
  std::string store;
  std::string grown;
  OutputArgs out;
  PipelineOptions options;
};

std::filesystem::path growth_folder(const std::string& store, const std::string& grown) {
  return grown.empty() ? std::filesystem::path(store + ".grown") : std::filesystem::path(grown);
}

std::filesystem::path growth_file(const std::filesystem::path& folder, std::size_t tile) {
  return folder / fmt::format("tile-{:06}.g2sgrow", tile);
}

// "A-B" (inclusive), "A", or empty (all), checked against the store's tile count.
std::pair<std::size_t, std::size_t> tile_range(const std::string& text, std::size_t tiles) {
  if (text.empty()) return {0, tiles};
  std::size_t first = 0, last = 0;
  const auto dash = text.find('-');
  try {
    std::size_t used = 0;
    first = std::stoul(text.substr(0, dash), &used);
    if (used != text.substr(0, dash).size()) throw std::invalid_argument(text);
    last = first;
    if (dash != std::string::npos) {
      last = std::stoul(text.substr(dash + 1), &used);
      if (used != text.size() - dash - 1) throw std::invalid_argument(text);
    }
  } catch (const std::exception&) {
    throw Error(Exit::usage, fmt::format("--tiles {}: expected A-B or A (tile indices)", text));
  }
  if (first > last) {
    throw Error(Exit::usage,
                fmt::format("--tiles {}: the range runs backwards (A-B with A <= B)", text));
  }
  if (last >= tiles) {
    throw Error(Exit::usage, fmt::format("--tiles {}: the store has tiles 0-{}", text, tiles - 1));
  }
  return {first, last + 1};
}

void run_grow(GrowArgs& args) {
  check_radius_steps(args.options.mesh.radius_steps);
  const TileStore store(args.store);
  const std::uint64_t fingerprint = source_fingerprint(store);
  const std::uint64_t options = options_fingerprint(args.options);
  const std::filesystem::path folder = growth_folder(args.store, args.grown);
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error || !std::filesystem::is_directory(folder)) {
    throw Error(Exit::write_failed,
                fmt::format("{}: cannot make the folder for the grown tiles: {}", folder.string(),
                            error ? error.message() : "a file is in the way"));
  }
  // Plain variables, not a structured binding: lambdas below capture them (clang before 16
  // refuses to capture bindings).
  const std::pair<std::size_t, std::size_t> range = tile_range(args.tiles, store.tiles().size());
  const std::size_t first = range.first, end = range.second;
  std::unique_ptr<tbb::global_control> limit;
  if (args.threads > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(args.threads));
  }
  Progress progress(!args.quiet);
  std::mutex lock;
  std::size_t done = 0;
  std::atomic<std::size_t> skipped = 0;
  const auto t0 = std::chrono::steady_clock::now();
  tbb::parallel_for(first, end, [&](std::size_t t) {
    const std::filesystem::path file = growth_file(folder, t);
    const auto tile = static_cast<std::uint32_t>(t);
    bool sound = false;
    if (std::filesystem::exists(file)) {
      try {
        read_tile_growth(file, tile, fingerprint, options);
        sound = true;
      } catch (const Error&) {
        sound = false;  // corrupt, from another store or other options: grow it again
      }
    }
    if (sound) {
      ++skipped;
    } else {
      write_tile_growth(file, tile, fingerprint, options, grow_tile(store, t, args.options));
    }
    const std::lock_guard guard(lock);
    progress.stage("growing", static_cast<double>(++done) / static_cast<double>(end - first));
  });
  progress.clear();
  if (args.quiet) return;
  fmt::print(stderr, "{}: tiles {}-{} grown ({} already there) in {:.2f} s\n", folder.string(),
             first, end - 1, skipped.load(),
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

void run_stitch(StitchArgs& args) {
  Progress progress(!args.out.quiet && !args.out.json);
  RunFacts facts{args.store, 0, 0, std::chrono::steady_clock::now(), {}, {}, {}};
  check_radius_steps(args.options.mesh.radius_steps);
  refuse_same_file({args.store}, args.out.output, "-o");
  const TileStore store(args.store);
  facts.non_finite = store.input_report().non_finite;
  const std::uint64_t fingerprint = source_fingerprint(store);
  const std::uint64_t options = options_fingerprint(args.options);
  const std::filesystem::path folder = growth_folder(args.store, args.grown);
  const std::size_t tiles = store.tiles().size();
  // Every growth file is checked before anything is stitched: a missing or corrupt one fails
  // the run at once, not after minutes of stitching.
  for (std::size_t t = 0; t < tiles; ++t) {
    read_tile_growth(growth_file(folder, t), static_cast<std::uint32_t>(t), fingerprint, options);
  }
  write_and_report(
      store,
      [&](MeshSink& sink) {
        Stitcher stitcher(store, args.options, sink);
        for (std::size_t t = 0; t < tiles; ++t) {
          const std::filesystem::path file = growth_file(folder, t);
          try {
            stitcher.add(
                t, read_tile_growth(file, static_cast<std::uint32_t>(t), fingerprint, options));
          } catch (const Error& e) {
            // The stitcher's own checks (corners, point counts, ids) do not know the files.
            if (e.code() != Exit::bad_input || std::string_view(e.what()).find(file.string()) == 0)
              throw;
            throw Error(e.code(), fmt::format("{}: tile {} of {}: {}", file.string(), t, args.store,
                                              e.what()));
          }
          progress.stage("stitching", static_cast<double>(t + 1) / static_cast<double>(tiles));
        }
        progress.clear();
        return stitcher.finish();
      },
      args.out, facts);
}

}  // namespace

void add_stage_commands(CLI::App& app) {
  auto grow = std::make_shared<GrowArgs>();
  CLI::App* g = app.add_subcommand(
      "grow", "Grow G2S in tiles of a tile store (made by g2s tile), one file per tile");
  g->add_option("store", grow->store, "Tile store")->required();
  g->add_option("--tiles", grow->tiles, "Tiles to grow: A-B (inclusive) or A; default all");
  g->add_option("--grown", grow->grown, "Folder for the grown tiles (default STORE.grown)");
  g->add_option("--threads", grow->threads, "Worker threads (default: all cores)")
      ->check(count_range(0, kMostThreads));
  g->add_flag("-q,--quiet", grow->quiet, "Print nothing on success");
  add_mesh_options(*g, grow->options);
  g->callback([grow] { run_grow(*grow); });

  auto stitch = std::make_shared<StitchArgs>();
  CLI::App* s = app.add_subcommand(
      "stitch", "Stitch the grown tiles of a tile store, clean up and write the mesh");
  s->add_option("store", stitch->store, "Tile store")->required();
  s->add_option("--grown", stitch->grown, "Folder of the grown tiles (default STORE.grown)");
  add_output_options(*s, stitch->out);
  add_mesh_options(*s, stitch->options);
  s->callback([stitch] { run_stitch(*stitch); });
}

}  // namespace g2s::cli
