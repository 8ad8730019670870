// Micro-benchmarks of the readers and writers (src/io): binary STL output of a mesh grown from a
// 200k-point synthetic sphere (write_mesh to a temporary file), and read_points of a 1M-point
// binary little-endian PLY (written once by write_synthetic_cloud to a temporary file). The files
// live in the system temporary folder and are removed at exit; both run through the page cache
// (the PLY was just written, so reads are hot), so these time the formatting and parsing, not the
// disk. Setup is built once per process and kept out of the timed loops.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"
#include "g2s/synth.hpp"

namespace {

namespace fs = std::filesystem;

// A file path in the temporary folder, unique to this process, removed at exit.
class TempPath {
 public:
  explicit TempPath(const std::string& name)
      : path_(fs::temp_directory_path() /
              ("g2s-bench-" + std::to_string(::getpid()) + "-" + name)) {}
  ~TempPath() {
    std::error_code ignored;
    fs::remove(path_, ignored);
  }
  TempPath(const TempPath&) = delete;
  TempPath& operator=(const TempPath&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

struct Mesh {
  g2s::PointCloud cloud;
  std::vector<g2s::Triangle> triangles;
};

const Mesh& sphere_mesh() {
  static const Mesh mesh = [] {
    g2s::SynthOptions options;
    options.shape = g2s::SynthShape::sphere;
    options.points = 200'000;
    Mesh m{g2s::make_synthetic_cloud(options), {}};
    m.triangles = g2s::mesh_cloud(m.cloud).triangles;
    return m;
  }();
  return mesh;
}

// write_mesh as binary STL (84 + 50 bytes per triangle), committed (renamed) every iteration.
void BM_WriteStlBinary(benchmark::State& state) {
  const Mesh& mesh = sphere_mesh();
  static const TempPath target("write.stl");
  for (auto _ : state) {
    g2s::write_mesh(target.path(), mesh.cloud.xyz, mesh.triangles, g2s::MeshFormat::stl_binary);
  }
  const auto triangles = static_cast<std::int64_t>(mesh.triangles.size());
  state.SetBytesProcessed(state.iterations() * (84 + 50 * triangles));
  state.SetItemsProcessed(state.iterations() * triangles);
  state.counters["triangles"] = static_cast<double>(triangles);
}
BENCHMARK(BM_WriteStlBinary)->Unit(benchmark::kMillisecond)->UseRealTime();

// read_points of a 1M-point binary little-endian PLY (float x, y, z; 12 MB).
void BM_ReadPlyBinary1M(benchmark::State& state) {
  constexpr std::uint64_t kPoints = 1'000'000;
  static const TempPath source("read.ply");
  static const bool written = [] {
    g2s::SynthOptions options;
    options.shape = g2s::SynthShape::sphere;
    options.points = kPoints;
    g2s::write_synthetic_cloud(source.path(), options);
    return true;
  }();
  benchmark::DoNotOptimize(written);
  std::size_t points = 0;
  for (auto _ : state) {
    const g2s::PointCloud cloud = g2s::read_points(source.path());
    points = cloud.size();
  }
  if (points != kPoints) state.SkipWithError("read_points returned the wrong number of points");
  state.SetBytesProcessed(state.iterations() *
                          static_cast<std::int64_t>(fs::file_size(source.path())));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kPoints));
}
BENCHMARK(BM_ReadPlyBinary1M)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
