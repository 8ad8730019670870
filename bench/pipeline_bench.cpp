// Micro-benchmarks of the tiled pipeline's serial end: the seam stitcher with its sweep (stitch,
// clean-up, release) over the grown tiles of a 1M-point torus cut into 24 tiles, into a sink
// that only counts; and the streaming writer (binary STL written in place, a third of the
// groups flipped at the end). Growth runs once, outside the timed loop. Items are triangles.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/synth.hpp"

namespace {

class CountingSink final : public g2s::MeshSink {
 public:
  void vertex(g2s::Index, const double*) override { ++vertices; }
  void triangle(const g2s::Triangle&, const std::array<const double*, 3>&, std::uint32_t) override {
    ++triangles;
  }
  void finish(std::span<const std::uint8_t>) override {}
  std::uint64_t vertices = 0;
  std::uint64_t triangles = 0;
};

struct GrownTorus {
  g2s::PointCloud cloud;
  std::unique_ptr<g2s::MemoryTiles> tiles;
  std::vector<g2s::TileGrowth> growth;
};

const GrownTorus& grown_torus() {
  static const GrownTorus torus = [] {
    GrownTorus t;
    g2s::SynthOptions o;
    o.shape = g2s::SynthShape::torus;
    o.points = 1'000'000;
    t.cloud = g2s::make_synthetic_cloud(o);
    t.tiles = std::make_unique<g2s::MemoryTiles>(t.cloud, 50'000);
    for (std::size_t k = 0; k < t.tiles->tiles().size(); ++k) {
      t.growth.push_back(g2s::grow_tile(*t.tiles, k, {}));
    }
    return t;
  }();
  return torus;
}

void BM_Stitch_Torus1M(benchmark::State& state) {
  const GrownTorus& torus = grown_torus();
  std::uint64_t triangles = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::vector<g2s::TileGrowth> growth = torus.growth;
    state.ResumeTiming();
    CountingSink sink;
    g2s::Stitcher stitcher(*torus.tiles, {}, sink);
    for (std::size_t k = 0; k < growth.size(); ++k) stitcher.add(k, std::move(growth[k]));
    stitcher.finish();
    triangles += sink.triangles;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(triangles));
  state.counters["tiles"] = static_cast<double>(torus.growth.size());
}
BENCHMARK(BM_Stitch_Torus1M)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_StreamStlBinary(benchmark::State& state) {
  constexpr std::uint32_t kSide = 1000;  // a kSide x kSide grid: 2M triangles
  std::vector<double> xyz;
  for (std::uint32_t i = 0; i < kSide; ++i) {
    for (std::uint32_t j = 0; j < kSide; ++j) {
      xyz.insert(xyz.end(), {i * 0.01, j * 0.01, 0.001 * std::sin(i * 0.1 + j * 0.07)});
    }
  }
  const std::filesystem::path target =
      std::filesystem::temp_directory_path() / ("g2s-bench-" + std::to_string(::getpid()) + ".stl");
  std::vector<std::uint8_t> flip(64);
  for (std::size_t g = 0; g < flip.size(); ++g) flip[g] = g % 3 == 1;
  std::uint64_t triangles = 0;
  for (auto _ : state) {
    g2s::MeshStreamWriter writer(target, g2s::MeshFormat::stl_binary);
    g2s::Index next = 0;
    for (std::uint32_t i = 0; i + 1 < kSide; ++i) {
      const auto group = i / 16 % 64;  // runs of 16 rows
      for (std::uint32_t j = 0; j + 1 < kSide; ++j) {
        const g2s::Index a = i * kSide + j, b = a + kSide, c = b + 1, d = a + 1;
        const double *pa = &xyz[3 * a], *pb = &xyz[3 * b], *pc = &xyz[3 * c], *pd = &xyz[3 * d];
        writer.vertex(a, pa);  // numbers are not used by STL; positions are
        writer.triangle({next, next, next}, {pa, pb, pc}, group);
        writer.triangle({next, next, next}, {pa, pc, pd}, group);
        ++next;
      }
    }
    writer.finish(flip);
    triangles += writer.triangles();
  }
  std::filesystem::remove(target);
  state.SetItemsProcessed(static_cast<std::int64_t>(triangles));
}
BENCHMARK(BM_StreamStlBinary)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
