// Micro-benchmarks of the mesher (src/pipeline, src/grow, src/cleanup) on synthetic clouds made
// in-process: the whole mesher as `g2s mesh` runs it (mesh_cloud: one tile, grown, stitched and
// cleaned) on a 200k-point sphere and a 200k-point noisy terrain, growth
// alone, the Gabriel walk alone, and the non-manifold vertex pass on a grown (not yet cleaned)
// mesh. Times are for
// comparison over commits on one machine, never asserted. Setup (clouds, grids, grown meshes)
// is built once per process and kept out of the timed loops.
//
// TBB is limited to G2S_BENCH_THREADS threads (default 1, as bench/run.py runs `g2s mesh
// --threads 1`), so the numbers do not depend on how busy the other cores are; the mesher
// benchmarks report wall-clock time (UseRealTime), so a parallel stage would still show up.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cstdint>
#include <cstdlib>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

#include "cleanup/cleanup.hpp"
#include "g2s/mesher.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/synth.hpp"
#include "grid/hash_grid.hpp"
#include "grow/gabriel_walk.hpp"
#include "grow/grower.hpp"

namespace {

std::size_t bench_threads() {
  const char* text = std::getenv("G2S_BENCH_THREADS");
  const long n = text ? std::strtol(text, nullptr, 10) : 1;
  return n > 0 ? static_cast<std::size_t>(n) : 1;
}
// Process-wide for every *_bench.cpp: alive from static initialisation to exit.
const tbb::global_control thread_limit(tbb::global_control::max_allowed_parallelism,
                                       bench_threads());

constexpr std::uint64_t kMeshPoints = 200'000;
constexpr double kTerrainNoise = 0.2;  // Gaussian sigma, in mean spacings

// A synthetic cloud, cached per (shape, points, noise).
const g2s::PointCloud& cloud_of(g2s::SynthShape shape, std::uint64_t n, double noise) {
  static std::map<std::pair<int, std::uint64_t>, g2s::PointCloud> cache;
  const std::pair<int, std::uint64_t> key{
      static_cast<int>(shape) * 1000 + static_cast<int>(noise * 100), n};
  auto it = cache.find(key);
  if (it == cache.end()) {
    g2s::SynthOptions options;
    options.shape = shape;
    options.points = n;
    options.noise = noise;
    it = cache.emplace(key, g2s::make_synthetic_cloud(options)).first;
  }
  return it->second;
}

// The same as the grower sees it (3 floats each).
const std::vector<float>& cloud_points(g2s::SynthShape shape, std::uint64_t n, double noise) {
  static std::map<const g2s::PointCloud*, std::vector<float>> cache;
  const g2s::PointCloud& cloud = cloud_of(shape, n, noise);
  auto it = cache.find(&cloud);
  if (it == cache.end()) {
    it = cache.emplace(&cloud, std::vector<float>(cloud.xyz.begin(), cloud.xyz.end())).first;
  }
  return it->second;
}

const std::vector<float>& sphere() {
  return cloud_points(g2s::SynthShape::sphere, kMeshPoints, 0);
}
const std::vector<float>& terrain() {
  return cloud_points(g2s::SynthShape::terrain, kMeshPoints, kTerrainNoise);
}

// The whole mesher (tiles in memory, grid, growth, clean-up, orientation) as mesh_cloud runs it:
// one tile for 200k points. Counter "triangles/s" = output triangles per wall-clock second.
void mesh_cloud_bench(benchmark::State& state, const g2s::PointCloud& cloud) {
  std::uint64_t triangles = 0;
  for (auto _ : state) {
    const g2s::PipelineMesh mesh = g2s::mesh_cloud(cloud);
    triangles += mesh.triangles.size();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(cloud.size()));
  state.counters["triangles"] =
      benchmark::Counter(static_cast<double>(triangles), benchmark::Counter::kAvgIterations);
  state.counters["triangles/s"] =
      benchmark::Counter(static_cast<double>(triangles), benchmark::Counter::kIsRate);
}

void BM_MeshCloud_Sphere200k(benchmark::State& state) {
  mesh_cloud_bench(state, cloud_of(g2s::SynthShape::sphere, kMeshPoints, 0));
}
BENCHMARK(BM_MeshCloud_Sphere200k)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MeshCloud_NoisyTerrain200k(benchmark::State& state) {
  mesh_cloud_bench(state, cloud_of(g2s::SynthShape::terrain, kMeshPoints, kTerrainNoise));
}
BENCHMARK(BM_MeshCloud_NoisyTerrain200k)->Unit(benchmark::kMillisecond)->UseRealTime();

// Growth alone (seeds, front steps: candidate search, Gabriel walk, priority queue) on a prebuilt
// grid. Each triangle is one front step, so "triangles/s" is front steps per second; on the noisy
// terrain the Gabriel walks are longer and more candidates fold.
void grow_bench(benchmark::State& state, const g2s::HashGrid& grid) {
  const g2s::MeshOptions options;
  std::uint64_t triangles = 0;
  for (auto _ : state) {
    const g2s::GrowResult grown = g2s::grow_mesh(grid, options);
    triangles += grown.triangles.size();
  }
  state.counters["triangles/s"] =
      benchmark::Counter(static_cast<double>(triangles), benchmark::Counter::kIsRate);
}

void BM_Grow_Sphere200k(benchmark::State& state) {
  static const g2s::HashGrid grid(sphere(), {});
  grow_bench(state, grid);
}
BENCHMARK(BM_Grow_Sphere200k)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Grow_NoisyTerrain200k(benchmark::State& state) {
  static const g2s::HashGrid grid(terrain(), {});
  grow_bench(state, grid);
}
BENCHMARK(BM_Grow_NoisyTerrain200k)->Unit(benchmark::kMillisecond)->UseRealTime();

// The non-manifold vertex pass on the noisy terrain's grown triangles (before cleanup), as grown
// (injected:0) and with a bow-tie added at every 100th vertex (injected:1: a triangle sharing
// only that vertex with the mesh, so the vertex has two fans and the pass must remove one; the
// grower may leave few or no non-manifold vertices, and this times the fixing path too). Every
// vertex is a suspect, as if the grower had flagged them all; the pass marks triangles and
// leaves its input alone. Counters: triangles in, vertices fixed and triangles removed per pass.
void BM_NonManifold_NoisyTerrain200k(benchmark::State& state) {
  struct Grown {
    std::vector<g2s::Triangle> triangles;
    std::size_t vertices = 0;
  };
  static const Grown grown = [] {
    const g2s::HashGrid grid(terrain(), {});
    return Grown{g2s::grow_mesh(grid, g2s::MeshOptions{}).triangles, grid.size()};
  }();
  static const Grown injected = [] {
    Grown g = grown;
    const auto n = static_cast<g2s::Index>(grown.vertices);
    auto next = n;
    for (g2s::Index v = 0; v < n; v += 100) {
      g.triangles.push_back({v, next, next + 1});
      next += 2;
    }
    g.vertices = next;
    return g;
  }();
  const Grown& input = state.range(0) ? injected : grown;
  std::vector<g2s::Index> every(input.vertices);
  std::iota(every.begin(), every.end(), g2s::Index{0});
  g2s::NonManifoldReport report;
  std::vector<std::uint8_t> dead;
  std::vector<g2s::Index> deferred;
  for (auto _ : state) {
    report =
        g2s::mark_non_manifold_fans(input.triangles, input.vertices, every, {}, dead, deferred);
    benchmark::DoNotOptimize(dead.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(input.triangles.size()));
  state.counters["triangles_in"] = static_cast<double>(input.triangles.size());
  state.counters["vertices_fixed"] = static_cast<double>(report.vertices_fixed);
  state.counters["triangles_removed"] = static_cast<double>(report.triangles_removed);
}
BENCHMARK(BM_NonManifold_NoisyTerrain200k)
    ->ArgName("injected")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The Gabriel walk alone, on the noisy terrain: for edges from 20,000 points to their nearest
// neighbour, the candidates are the points within twice the edge's length of its midpoint, about
// what the larger radius levels gather (gathered once, outside the timed loop).
void BM_GabrielWalk_NoisyTerrain200k(benchmark::State& state) {
  const g2s::HashGrid grid(terrain(), {});
  struct Edge {
    g2s::Vec3 a, b;
    std::vector<g2s::WalkPoint> candidates;
  };
  std::vector<Edge> edges;
  for (std::uint32_t i = 0; i < grid.size() && edges.size() < 20'000; i += 10) {
    const std::uint32_t j = grid.nearest(i, 4 * grid.spacing(), [](std::uint32_t) { return true; });
    if (j == g2s::kNoIndex) continue;
    Edge e{grid.position(i), grid.position(j), {}};
    const g2s::Vec3 mid = (e.a + e.b) * 0.5;
    grid.for_each_in_ball(mid, 2 * std::max(norm(e.b - e.a), grid.spacing()),
                          [&](std::uint32_t k, double) {
                            const g2s::Vec3 q = grid.position(k);
                            if (k != i && k != j) e.candidates.push_back({q, norm2(q - mid), k});
                          });
    if (!e.candidates.empty()) edges.push_back(std::move(e));
  }
  std::vector<g2s::WalkPoint> scratch;
  std::uint64_t walks = 0;
  for (auto _ : state) {
    for (const Edge& e : edges) {
      scratch.assign(e.candidates.begin(), e.candidates.end());
      benchmark::DoNotOptimize(g2s::gabriel_walk(e.a, e.b, scratch));
    }
    walks += edges.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(walks));
  state.counters["candidates/edge"] = static_cast<double>([&] {
                                        std::size_t n = 0;
                                        for (const Edge& e : edges) n += e.candidates.size();
                                        return n;
                                      }()) /
                                      static_cast<double>(edges.size());
}
BENCHMARK(BM_GabrielWalk_NoisyTerrain200k)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
