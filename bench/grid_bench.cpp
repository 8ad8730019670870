// Micro-benchmarks of the flat hash grid (src/grid): building it (Morton radix sort, duplicate
// merge, hashed cells, spacing estimate), fixed-radius ball queries and nearest-point queries, on
// an evenly sampled synthetic unit sphere. Times are for comparison over commits on one machine,
// never asserted. Setup (the clouds, the grid for the query benchmark) is built once per process
// and kept out of the timed loops.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <map>
#include <vector>

#include "g2s/synth.hpp"
#include "grid/hash_grid.hpp"

namespace {

// The sphere's points as the mesher sees them (3 floats each), cached per size.
const std::vector<float>& sphere_points(std::uint64_t n) {
  static std::map<std::uint64_t, std::vector<float>> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    g2s::SynthOptions options;
    options.shape = g2s::SynthShape::sphere;
    options.points = n;
    const g2s::PointCloud cloud = g2s::make_synthetic_cloud(options);
    it = cache.emplace(n, std::vector<float>(cloud.xyz.begin(), cloud.xyz.end())).first;
  }
  return it->second;
}

// Grid build over 100k and 1M points; items = points.
void BM_GridBuild(benchmark::State& state) {
  const auto& xyz = sphere_points(static_cast<std::uint64_t>(state.range(0)));
  for (auto _ : state) {
    g2s::HashGrid grid(xyz, {});
    benchmark::DoNotOptimize(grid.size());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_GridBuild)
    ->ArgName("points")
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One ball query per iteration on the 1M-point sphere's grid, centred on grid points taken in a
// scattered order (stride 7919), radius = arg/10 mean spacings (the grower's search balls are
// 1-3 front-edge lengths). Counter "neighbours" = mean points found per query.
void BM_BallQuery(benchmark::State& state) {
  static const g2s::HashGrid grid(sphere_points(1'000'000), {});
  const double radius = static_cast<double>(state.range(0)) / 10.0 * grid.spacing();
  std::uint32_t i = 0;
  std::uint64_t found = 0;
  for (auto _ : state) {
    grid.for_each_in_ball(grid.position(i), radius, [&](std::uint32_t, double) { ++found; });
    i = (i + 7919) % grid.size();
  }
  benchmark::DoNotOptimize(found);
  state.SetItemsProcessed(state.iterations());
  state.counters["neighbours"] =
      benchmark::Counter(static_cast<double>(found), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_BallQuery)->ArgName("radius_x10")->Arg(10)->Arg(20)->Arg(30);

// One nearest-neighbour query per iteration on the 1M-point sphere's grid (the seed search's
// first step: the nearest other point within 4 spacings), points taken in the same scattered
// order as BM_BallQuery.
void BM_Nearest(benchmark::State& state) {
  static const g2s::HashGrid grid(sphere_points(1'000'000), {});
  const double max_radius = 4.0 * grid.spacing();
  std::uint32_t i = 0;
  std::uint64_t found = 0;
  for (auto _ : state) {
    found += grid.nearest(i, max_radius, [](std::uint32_t) { return true; }) != g2s::kNoIndex;
    i = (i + 7919) % grid.size();
  }
  benchmark::DoNotOptimize(found);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Nearest);

}  // namespace
