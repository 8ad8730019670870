// `g2s tile INPUT STORE [--tile-points N] [--compress]`: cuts a cloud into a tile store
// (docs/tile-store.md) in bounded memory; `g2s tile-info STORE`: prints a store's header and
// its tiles. A corrupt, truncated or foreign store exits 3 through g2s::Error.
#include <fmt/core.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "g2s/tile_stages.hpp"
#include "g2s/tile_store.hpp"
#include "json_writer.hpp"
#include "progress.hpp"

namespace g2s::cli {
namespace {

struct TileArgs {
  std::string input;
  std::string store;
  bool quiet = false;
  bool json = false;
  TileStoreOptions options;
};

struct TileInfoArgs {
  std::string store;
  bool json = false;
};

std::string box_json(const TileBox& b) {
  return fmt::format("{{\"lo\":[{},{},{}],\"hi\":[{},{},{}]}}", b.lo[0], b.lo[1], b.lo[2], b.hi[0],
                     b.hi[1], b.hi[2]);
}

void run_tile(TileArgs& args) {
  refuse_same_file({args.input}, args.store, "the store");
  Progress progress(!args.quiet && !args.json);
  const auto t0 = std::chrono::steady_clock::now();
  progress.stage("tiling", 0);
  args.options.progress = [&](std::uint64_t done, std::uint64_t total) {
    progress.stage("tiling",
                   total > 0 ? static_cast<double>(done) / static_cast<double>(total) : 1.0);
  };
  const TileStoreReport r = build_tile_store(args.input, args.store, args.options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress.clear();
  if (args.json) {
    JsonObject json;
    json.text("input", args.input)
        .text("store", args.store)
        .text("format", r.read.format)
        .number("points", r.read.points)
        .number("non_finite", r.read.non_finite)
        .number("tiles", r.tiles)
        .number("tile_points", args.options.tile_points)
        .number("compressed", args.options.compress)
        .number("bytes", r.bytes)
        .fixed("seconds", seconds, 3)
        .fixed("peak_rss_mb", peak_rss_mb(), 1);
    fmt::print("{}\n", json.str());
    return;
  }
  if (args.quiet) return;
  fmt::print(stderr, "{}: {} points -> {} tiles, {} bytes{} in {:.2f} s, peak {:.0f} MB\n",
             args.store, r.read.points, r.tiles, r.bytes, args.options.compress ? " (zstd)" : "",
             seconds, peak_rss_mb());
}

void run_tile_info(const TileInfoArgs& args) {
  const TileStore store(args.store);
  // Every block is read once, so a corrupt frame fails here (exit 3), not in a later stage.
  for (std::size_t t = 0; t < store.tiles().size(); ++t) store.load(t);
  const ReadReport& in = store.input_report();
  const TileBox& b = store.bounds();
  // The neighbours' points each tile grows with (g2s grow's default halo): what a tile costs to
  // grow is its points and these.
  const std::vector<std::uint64_t> halo = count_halo_points(store, PipelineOptions{});
  if (args.json) {
    JsonObject input;
    input.text("format", in.format)
        .number("declared", in.declared)
        .number("points", in.points)
        .number("non_finite", in.non_finite);
    std::string tiles = "[";
    for (std::size_t t = 0; t < store.tiles().size(); ++t) {
      const TileInfo& info = store.tiles()[t];
      JsonObject tile;
      tile.number("points", info.points)
          .number("halo_points", halo[t])
          .number("spacing", info.spacing)
          .raw("box", box_json(info.box));
      tiles += (t > 0 ? "," : "") + tile.str();
    }
    JsonObject json;
    json.text("store", args.store)
        .number("points", store.point_count())
        .number("compressed", store.compressed())
        .raw("bounds", box_json(b))
        .number("spacing", store.cloud_spacing())
        .number("group_distance", store.group_distance())
        .number("twin_distance", store.twin_distance())
        .raw("input", input.str())
        .raw("tiles", tiles + "]");
    fmt::print("{}\n", json.str());
    return;
  }
  fmt::print("store:      {}\n", args.store);
  fmt::print("points:     {}\n", store.point_count());
  fmt::print("tiles:      {}\n", store.tiles().size());
  fmt::print("blocks:     {}\n", store.compressed() ? "zstd" : "raw");
  fmt::print("bounds:     [{}, {}, {}] - [{}, {}, {}]\n", b.lo[0], b.lo[1], b.lo[2], b.hi[0],
             b.hi[1], b.hi[2]);
  fmt::print("spacing:    {:.6g} (the cloud's median nearest-neighbour distance)\n",
             store.cloud_spacing());
  if (store.group_distance() > 0) {
    fmt::print("groups:     points come in groups: the spacing is measured beyond {:.6g}\n",
               store.group_distance());
  }
  if (store.twin_distance() > 0) {
    fmt::print("twins:      points within {:.6g} of each other are taken as one\n",
               store.twin_distance());
  }
  fmt::print("input:      {}, {} declared, {} points, {} non-finite dropped\n", in.format,
             in.declared, in.points, in.non_finite);
  fmt::print("{:>6} {:>10} {:>10} {:>12}  box\n", "tile", "points", "halo", "spacing");
  for (std::size_t t = 0; t < store.tiles().size(); ++t) {
    const TileInfo& info = store.tiles()[t];
    const TileBox& x = info.box;
    fmt::print(
        "{:>6} {:>10} {:>10} {:>12.6g}  [{:.6g}, {:.6g}, {:.6g}] - [{:.6g}, {:.6g}, {:.6g}]\n", t,
        info.points, halo[t], info.spacing, x.lo[0], x.lo[1], x.lo[2], x.hi[0], x.hi[1], x.hi[2]);
  }
}

}  // namespace

void add_tile_commands(CLI::App& app) {
  auto args = std::make_shared<TileArgs>();
  CLI::App* cmd = app.add_subcommand(
      "tile", "Cut a point cloud into a tile store for the out-of-core pipeline (bounded memory)");
  cmd->add_option("input", args->input, "Point cloud: PLY (ascii/binary), LAS or text XYZ/PTS")
      ->required();
  cmd->add_option("store", args->store, "Tile store to write (one file, written atomically)")
      ->required();
  cmd->add_option("--tile-points", args->options.tile_points,
                  "Most points in a tile (default 1048576, at least 500); dense regions get "
                  "smaller tiles")
      ->check(count_range(kFewestTilePoints, 0xFFFFFFFF));
  cmd->add_flag("--compress", args->options.compress,
                "zstd-compress the blocks (in 16k-point frames, so borders load without the rest)");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
  cmd->add_flag("--json", args->json, "Print the summary as one JSON object on stdout");
  cmd->callback([args] { run_tile(*args); });

  auto info_args = std::make_shared<TileInfoArgs>();
  CLI::App* info = app.add_subcommand(
      "tile-info",
      "Check a tile store (header, table and every block's checksums) and print its header and "
      "tiles; exit 3 if it is corrupt");
  info->add_option("store", info_args->store, "Tile store written by g2s tile")->required();
  info->add_flag("--json", info_args->json, "Print as one JSON object on stdout");
  info->callback([info_args] { run_tile_info(*info_args); });
}

}  // namespace g2s::cli
