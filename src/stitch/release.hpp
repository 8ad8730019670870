// The global clean-up of the tiled pipeline, run after every stitched tile on the points that
// tile finishes (docs/algorithm.md, "Non-manifold vertices", applied as the sweep goes): their
// extra fans are removed, then every live triangle whose corners are all finished is handed to the
// sink and leaves memory.
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

// Adds triangle `ids` with corner positions `xyz` to its group's orientation sums. origin:
// subtracted from positions in the sums (the cloud's centre, so they keep their precision).
void add_to_sums(GroupSums& sums, const std::array<const double*, 3>& xyz, const Vec3& origin,
                 const Triangle& ids);

// Hands one triangle to the sink: corners without a vertex number (kNoIndex in *number[k]) get
// the next one, in order of first use; the triangle joins its group's orientation sums.
void emit_triangle(const std::array<std::uint32_t*, 3>& number,
                   const std::array<const double*, 3>& xyz, const Triangle& ids, GroupSums& sums,
                   std::uint32_t group, const Vec3& origin, MeshSink& sink, ReleaseCounts& counts);

void release_finished(LiveMesh& live, std::size_t step, const Vec3& origin, MeshSink& sink,
                      ReleaseCounts& counts);

}  // namespace g2s
