// Micro-benchmarks of the front step's bookkeeping (src/common/edge_map.hpp,
// src/grow/bucket_queue.hpp; docs/algorithm.md §3-4), which grow_mesh runs once per triangle: the
// Point-Edge Map replaying a grown mesh triangle by triangle (one find and one add per edge, as
// the grower does when it adds a triangle), and the discrete priority queue pushing and popping
// front edges. The Gabriel walk and the candidate search are private to src/grow/grower.cpp, so
// they are timed with the whole growth (BM_Grow_* in mesher_bench.cpp). Times are for comparison
// over commits on one machine, never asserted; setup is built once per process.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "common/edge_map.hpp"
#include "g2s/synth.hpp"
#include "grid/hash_grid.hpp"
#include "grow/bucket_queue.hpp"
#include "grow/grower.hpp"

namespace {

struct Grown {
  std::vector<g2s::Triangle>
      triangles;  // in growth order, so the edges come as the front makes them
  std::size_t vertices = 0;
};

// The triangles grown over a 200k-point synthetic sphere (grid indices, Morton-ordered points).
const Grown& grown_sphere() {
  static const Grown grown = [] {
    g2s::SynthOptions options;
    options.shape = g2s::SynthShape::sphere;
    options.points = 200'000;
    const g2s::PointCloud cloud = g2s::make_synthetic_cloud(options);
    const std::vector<float> xyz(cloud.xyz.begin(), cloud.xyz.end());
    const g2s::HashGrid grid(xyz, {});
    return Grown{g2s::grow_mesh(grid, g2s::MeshOptions{}).triangles, grid.size()};
  }();
  return grown;
}

// Every triangle's three edges looked up and recorded in a fresh Point-Edge Map, in growth
// order; items = triangles.
void BM_PointEdgeMap_Replay(benchmark::State& state) {
  const Grown& grown = grown_sphere();
  std::uint64_t closed = 0;
  for (auto _ : state) {
    g2s::EdgeMap edges(grown.vertices);
    for (std::uint32_t t = 0; t < grown.triangles.size(); ++t) {
      const g2s::Triangle& tri = grown.triangles[t];
      for (int k = 0; k < 3; ++k) {
        const g2s::Index u = tri[k], v = tri[(k + 1) % 3];
        closed += edges.find(u, v) != g2s::EdgeMap::kMissing;
        edges.add(u, v, t);
      }
    }
    benchmark::DoNotOptimize(edges.size());
  }
  benchmark::DoNotOptimize(closed);
  state.SetItemsProcessed(state.iterations() *
                          static_cast<std::int64_t>(grown_sphere().triangles.size()));
}
BENCHMARK(BM_PointEdgeMap_Replay)->Unit(benchmark::kMillisecond)->UseRealTime();

// The front as the grower drives its queue: every triangle pushes its new edges at level 0 and
// one front edge is popped per triangle; one edge in four is re-queued at a worse level (as an
// edge whose candidate is folded or far is). Levels = 4 radius levels x 4 flatness levels, the
// defaults; items = pops.
void BM_BucketQueue_Front(benchmark::State& state) {
  struct Edge {
    g2s::Index a, b;
    std::uint32_t triangle;
    g2s::Index cand;
  };
  constexpr int kLevels = 16;
  const Grown& grown = grown_sphere();
  std::uint64_t pops = 0;
  for (auto _ : state) {
    g2s::BucketQueue<Edge> queue(kLevels);
    Edge e{};
    std::uint32_t t = 0;
    for (const g2s::Triangle& tri : grown.triangles) {
      queue.push(0, {tri[0], tri[1], t, g2s::kNoIndex});
      queue.push(0, {tri[1], tri[2], t, g2s::kNoIndex});
      const int level = queue.pop(e);
      ++pops;
      if ((e.a & 3) == 0 && level + 1 < kLevels) queue.push(level + 1, e);
      ++t;
    }
    while (!queue.empty()) {
      queue.pop(e);
      ++pops;
    }
    benchmark::DoNotOptimize(e);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(pops));
}
BENCHMARK(BM_BucketQueue_Front)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
