// The summary's defects of a mesh file written by a run (measure_written_mesh in
// g2s/pipeline.hpp): the count made as the mesh streamed out where it is the file's, else the
// file read back, so that `g2s mesh` and the Python module's mesh_file report the same way.
#include "g2s/io.hpp"
#include "g2s/pipeline.hpp"

namespace g2s {

WrittenMeshStats measure_written_mesh(const StreamStats& counter, const std::filesystem::path& file,
                                      bool stl, double float_rounding, double spacing,
                                      std::uint64_t triangles, std::uint64_t memory_bytes) {
  if (counter.complete() && (!stl || float_rounding <= 0.01 * spacing)) {
    return {counter.stats(), true};
  }
  if (memory_bytes == 0 || triangles * kStatsBytesPerTriangle <= memory_bytes) {
    return {compute_stats(read_mesh(file)), false};
  }
  return {};
}

}  // namespace g2s
