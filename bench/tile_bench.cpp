// Micro-benchmarks of the tile store (src/tiling): loading one tile, and the border prefix a
// neighbour needs, from a raw and from a zstd store of the same 1M-point synthetic sphere
// (written once per process to the temporary folder by write_synthetic_cloud and
// build_tile_store at 250k points per tile: eight octants of 125k points, eight 16k-point
// frames each). Reads
// come from the page cache: this times checksums, decompression and decoding, not the disk.
// Setup is built once per process and kept out of the timed loops.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include "g2s/synth.hpp"
#include "g2s/tile_store.hpp"

namespace {

namespace fs = std::filesystem;

// The synthetic cloud and its two stores, in a folder unique to this process, removed at exit.
class Stores {
 public:
  Stores() : dir_(fs::temp_directory_path() / ("g2s-bench-tiles-" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
    g2s::SynthOptions synth;
    synth.shape = g2s::SynthShape::sphere;
    synth.points = 1'000'000;
    g2s::write_synthetic_cloud(dir_ / "cloud.ply", synth);
    g2s::TileStoreOptions options;
    options.tile_points = 250'000;
    g2s::build_tile_store(dir_ / "cloud.ply", dir_ / "raw.tiles", options);
    options.compress = true;
    g2s::build_tile_store(dir_ / "cloud.ply", dir_ / "zstd.tiles", options);
    raw = std::make_unique<g2s::TileStore>(dir_ / "raw.tiles");
    zstd = std::make_unique<g2s::TileStore>(dir_ / "zstd.tiles");
  }
  ~Stores() {
    raw.reset();
    zstd.reset();
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  Stores(const Stores&) = delete;
  Stores& operator=(const Stores&) = delete;
  std::unique_ptr<g2s::TileStore> raw;
  std::unique_ptr<g2s::TileStore> zstd;

 private:
  fs::path dir_;
};

const Stores& stores() {
  static const Stores s;
  return s;
}

const g2s::TileStore& store_for(const benchmark::State& state) {
  return state.range(0) == 0 ? *stores().raw : *stores().zstd;
}

// load() of the largest tile; arg 0 = raw store, 1 = zstd store.
void BM_TileLoad(benchmark::State& state) {
  const g2s::TileStore& store = store_for(state);
  std::size_t tile = 0;
  for (std::size_t t = 0; t < store.tiles().size(); ++t) {
    if (store.tiles()[t].points > store.tiles()[tile].points) tile = t;
  }
  std::size_t points = 0;
  for (auto _ : state) {
    const g2s::TilePoints pts = store.load(tile);
    points = pts.size();
    benchmark::DoNotOptimize(pts.xyz.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points));
  state.counters["points"] = static_cast<double>(points);
  state.counters["store_mb"] = static_cast<double>(fs::file_size(store.path())) / 1e6;
}
BENCHMARK(BM_TileLoad)
    ->ArgName("zstd")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// load_border() of the same tile with a halo 4 spacings wide: only its first frame is read.
void BM_TileLoadBorder(benchmark::State& state) {
  const g2s::TileStore& store = store_for(state);
  std::size_t tile = 0;
  for (std::size_t t = 0; t < store.tiles().size(); ++t) {
    if (store.tiles()[t].points > store.tiles()[tile].points) tile = t;
  }
  const double halo = 4 * store.tiles()[tile].spacing;
  std::size_t points = 0;
  for (auto _ : state) {
    const g2s::TilePoints pts = store.load_border(tile, halo);
    points = pts.size();
    benchmark::DoNotOptimize(pts.xyz.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points));
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_TileLoadBorder)
    ->ArgName("zstd")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
