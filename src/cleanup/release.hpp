// The global clean-up of the tiled pipeline, run after every stitched tile on the points that
// tile finishes (ALGORITHM.md §6 applied as the sweep goes): their extra fans are removed, then
// every live triangle whose corners are all finished is handed to the sink and leaves memory.
#pragma once

#include <cstddef>

#include "g2s/mesh_sink.hpp"
#include "stitch/live_mesh.hpp"

namespace g2s {

struct ReleaseCounts {
  NonManifoldReport non_manifold;
  std::uint64_t triangles = 0;  // handed to the sink
  std::uint32_t vertices = 0;   // numbered so far
};

// origin: subtracted from positions in the orientation sums (the cloud's centre, so they keep
// their precision).
void release_finished(LiveMesh& live, std::size_t step, const Vec3& origin, MeshSink& sink,
                      ReleaseCounts& counts);

}  // namespace g2s
