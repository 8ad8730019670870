// Micro-benchmark of the mesh defect measurement (src/stats): compute_stats on a mesh of about
// 1M triangles grown from a 500k-point synthetic sphere (a closed mesh has 2 triangles per
// vertex), without and with the coverage of the input cloud. Times are for comparison over
// commits on one machine, never asserted. The mesh is built once per process, outside the
// timed loops.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/triangle_intersection.hpp"
#include "g2s/mesher.hpp"
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

// The same mesh moved to georeferenced coordinates (UTM-sized: 5e5 east, 5e6 north): the crossing
// count's float boxes are taken from the mesh's low corner, or every box would be half a metre
// wide there and a grid bucket would hold a sizeable part of the mesh (a millimetre-spaced
// raw-bunny mesh so moved took 6 minutes to measure before, 1.5 s after).
void BM_ComputeStats1MGeoreferenced(benchmark::State& state) {
  static const g2s::IndexedMesh moved = [] {
    g2s::IndexedMesh m = million_triangles().mesh;
    const double offset[3] = {512345.678, 5123456.789, 312.5};
    for (std::size_t k = 0; k < m.xyz.size(); ++k) m.xyz[k] += offset[k % 3];
    return m;
  }();
  g2s::MeshStats stats;
  for (auto _ : state) {
    stats = g2s::compute_stats(moved);
    benchmark::DoNotOptimize(stats.triangles);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(moved.triangles.size()));
  state.counters["triangles"] = static_cast<double>(stats.triangles);
  state.counters["crossing_pairs"] = static_cast<double>(stats.crossing_pairs);
}
BENCHMARK(BM_ComputeStats1MGeoreferenced)->Unit(benchmark::kMillisecond)->UseRealTime();

// triangles_cross on the pairs the mesher would ask about: triangles of the sphere's mesh, as
// float triangles, against the next 16 in mesher order (neighbours in space); with argument 1
// only the pairs whose bounding boxes overlap (mostly sharing a corner or an edge). Items are
// calls.
void BM_TrianglesCross(benchmark::State& state) {
  const Fixture& f = million_triangles();
  constexpr std::size_t kTriangles = 20000, kNext = 16;
  std::vector<g2s::Vec3f> tri(3 * kTriangles);
  for (std::size_t t = 0; t < kTriangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const double* p = &f.mesh.xyz[3 * std::size_t{f.mesh.triangles[t][k]}];
      tri[3 * t + k] = {static_cast<float>(p[0]), static_cast<float>(p[1]),
                        static_cast<float>(p[2])};
    }
  }
  auto boxes_overlap = [&](std::size_t t, std::size_t u) {
    for (int k = 0; k < 3; ++k) {
      auto coordinate = [&](std::size_t i, int c) {
        const g2s::Vec3f& v = tri[3 * i + c];
        return k == 0 ? v.x : (k == 1 ? v.y : v.z);
      };
      const float t_lo = std::min({coordinate(t, 0), coordinate(t, 1), coordinate(t, 2)});
      const float t_hi = std::max({coordinate(t, 0), coordinate(t, 1), coordinate(t, 2)});
      const float u_lo = std::min({coordinate(u, 0), coordinate(u, 1), coordinate(u, 2)});
      const float u_hi = std::max({coordinate(u, 0), coordinate(u, 1), coordinate(u, 2)});
      if (t_hi < u_lo || u_hi < t_lo) return false;
    }
    return true;
  };
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t t = 0; t + kNext < kTriangles; ++t) {
    for (std::size_t u = t + 1; u <= t + kNext; ++u) {
      if (state.range(0) == 0 || boxes_overlap(t, u)) pairs.emplace_back(t, u);
    }
  }
  std::int64_t crossing = 0;
  for (auto _ : state) {
    for (const auto& [t, u] : pairs) crossing += g2s::triangles_cross(&tri[3 * t], &tri[3 * u]);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(pairs.size()));
  state.counters["pairs"] = static_cast<double>(pairs.size());
  state.counters["crossing"] = static_cast<double>(crossing);
}
BENCHMARK(BM_TrianglesCross)->ArgName("overlapping")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
