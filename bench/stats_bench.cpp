// Micro-benchmark of the mesh defect measurement (src/stats): compute_stats on a mesh of about
// 1M triangles grown from a 500k-point synthetic sphere (a closed mesh has 2 triangles per
// vertex), without and with the coverage of the input cloud. Times are for comparison over
// commits on one machine, never asserted. The mesh is built once per process, outside the
// timed loops.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "g2s/pipeline.hpp"
#include "g2s/stats.hpp"
#include "g2s/synth.hpp"

namespace {

struct Fixture {
  g2s::PointCloud cloud;
  g2s::IndexedMesh mesh;
};

const Fixture& million_triangles() {
  static const Fixture fixture = [] {
    g2s::SynthOptions options;
    options.shape = g2s::SynthShape::sphere;
    options.points = 500'002;  // 2 * 500'002 - 4 = 1'000'000 triangles when closed
    Fixture f;
    f.cloud = g2s::make_synthetic_cloud(options);
    f.mesh.triangles = g2s::mesh_cloud(f.cloud).triangles;
    f.mesh.xyz = f.cloud.xyz;
    return f;
  }();
  return fixture;
}

// Counters: triangles measured, and non-manifold vertices + boundary edges found (a check that
// the work was done, and a hint when the mesher's output changes).
void BM_ComputeStats1M(benchmark::State& state) {
  const Fixture& f = million_triangles();
  const bool coverage = state.range(0) != 0;
  g2s::MeshStats stats;
  for (auto _ : state) {
    stats = g2s::compute_stats(f.mesh, coverage ? &f.cloud : nullptr);
    benchmark::DoNotOptimize(stats.triangles);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f.mesh.triangles.size()));
  state.counters["triangles"] = static_cast<double>(stats.triangles);
  state.counters["boundary_edges"] = static_cast<double>(stats.boundary_edges);
  state.counters["nm_vertices"] = static_cast<double>(stats.non_manifold_vertices);
}
BENCHMARK(BM_ComputeStats1M)
    ->ArgName("coverage")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
