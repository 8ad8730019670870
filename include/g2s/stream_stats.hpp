// Defects counted while a mesh streams to its sink (src/stats/stream_stats.cpp), so that
// `g2s mesh` reports them without reading the written file back: the counts are those of
// compute_stats on that file, in memory that follows the vertices still open, not the mesh.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "g2s/mesh_sink.hpp"
#include "g2s/stats.hpp"

namespace g2s {

// A MeshSink that passes everything on to `next` and counts the mesh's defects on the way.
// Positions are taken as the file will hold them: rounded to float when `float_positions` (STL),
// exact otherwise (PLY keeps every coordinate). The vertices are welded by those positions and
// degenerate and duplicate triangles set aside exactly as compute_stats does. When
// `positions_distinct`, the caller promises that no two vertices share a position as stored, and
// the welding (a hash probe per vertex, the count's largest cost) is skipped: the pipeline's
// vertices are distinct input points, so this holds for PLY, and for STL when every input
// coordinate is exactly a float. A vertex's edges
// and fans are counted when the sink is told it is done (vertex_done), the orientation
// conflicts between groups once finish() gives the groups' flips.
//
// Outputs (stats(), after finish()): every count of MeshStats except coverage (has_coverage is
// false) and the crossing pairs, which need the whole mesh. complete() is false when a triangle
// came for a vertex already announced done (the counts are then not those of the file).
// peak_bytes(): the most memory the counter held at any time (its open vertices and their
// stars, its tables), in bytes.
class StreamStats final : public MeshSink {
 public:
  StreamStats(MeshSink& next, bool float_positions, bool positions_distinct);
  ~StreamStats() override;
  StreamStats(const StreamStats&) = delete;
  StreamStats& operator=(const StreamStats&) = delete;

  void vertex(Index id, const double xyz[3]) override;
  void triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                std::uint32_t group) override;
  void vertex_done(std::uint32_t vertex) override;
  // A block is counted ahead where no welding is needed (positions_distinct): its triangles,
  // the stars of the vertices it says are done, and how it joins the others, which the counter
  // then holds open as if the block had come triangle by triangle.
  std::unique_ptr<SinkBlockWork> prepare(const SinkBlock& block) const override;
  void block(const SinkBlock& block, std::uint32_t first_vertex, std::uint32_t first_group,
             std::unique_ptr<SinkBlockWork> work) override;
  void finish(std::span<const std::uint8_t> flip) override;

  const MeshStats& stats() const;
  bool complete() const;
  std::uint64_t peak_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace g2s
