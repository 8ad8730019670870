// Micro-benchmarks of the mesher's hot stages on a synthetic sphere: grid build, ball query,
// the whole in-memory mesher. Times are for comparison over commits, never asserted.
#include <benchmark/benchmark.h>

#include "g2s/mesher.hpp"
#include "g2s/synth.hpp"
#include "grid/hash_grid.hpp"

namespace {

std::vector<float> sphere_points(std::uint64_t n) {
  const g2s::PointCloud cloud = g2s::make_synthetic_cloud({g2s::SynthShape::sphere, n});
  return {cloud.xyz.begin(), cloud.xyz.end()};
}

void BM_GridBuild(benchmark::State& state) {
  const auto xyz = sphere_points(static_cast<std::uint64_t>(state.range(0)));
  for (auto _ : state) {
    g2s::HashGrid grid(xyz, {});
    benchmark::DoNotOptimize(grid.size());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_GridBuild)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);

void BM_BallQuery(benchmark::State& state) {
  const auto xyz = sphere_points(1'000'000);
  const g2s::HashGrid grid(xyz, {});
  const double radius = 2.0 * grid.spacing();
  std::uint32_t i = 0;
  std::uint64_t found = 0;
  for (auto _ : state) {
    grid.for_each_in_ball(grid.position(i), radius, [&](std::uint32_t, double) { ++found; });
    i = (i + 7919) % grid.size();
  }
  benchmark::DoNotOptimize(found);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BallQuery);

void BM_MeshSphere(benchmark::State& state) {
  const auto xyz = sphere_points(static_cast<std::uint64_t>(state.range(0)));
  std::uint64_t triangles = 0;
  for (auto _ : state) {
    const g2s::TileMesh mesh = g2s::mesh_tile(xyz, {}, {});
    triangles += mesh.triangles.size();
  }
  state.counters["triangles/s"] =
      benchmark::Counter(static_cast<double>(triangles), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MeshSphere)->Arg(200'000)->Unit(benchmark::kMillisecond);

}  // namespace
