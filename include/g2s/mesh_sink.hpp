// Where the tiled pipeline hands its mesh: a triangle at a time, as soon as nothing more can
// change it, so the whole mesh never has to be in memory. Only the orientation is decided at
// the end, for whole orientation groups at once (a group's triangles face one way).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>

#include "g2s/types.hpp"

namespace g2s {

// Triangles handed on at once whose corners are all new (no triangle before them used one): the
// final triangles of a tile. Vertices are numbered from 0 in order of first use, groups from 0.
struct SinkBlock {
  std::span<const Index> ids;            // per vertex: its point's global id
  std::span<const double> xyz;           // per vertex: x, y, z
  std::span<const Triangle> triangles;   // by vertex number
  std::span<const std::uint32_t> group;  // per triangle
  // (triangle, vertex): the vertex gets no triangle after that one, in increasing triangle order.
  std::span<const std::pair<std::uint32_t, std::uint32_t>> done;
};

// What a sink worked out ahead on a block (MeshSink::prepare), handed back with it.
struct SinkBlockWork {
  virtual ~SinkBlockWork() = default;
};

class MeshSink {
 public:
  virtual ~MeshSink() = default;
  // The next vertex (numbered 0, 1, 2, ... in the order given): its point's global id and
  // position. Given before the first triangle that uses it.
  virtual void vertex(Index id, const double xyz[3]) = 0;
  // A finished triangle, by vertex number and with its corners' positions, as its orientation
  // group stores it.
  virtual void triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                        std::uint32_t group) = 0;
  // Vertex `vertex` (a number given by vertex()) is in no triangle still to come: its star is
  // complete. A sink that counts defects in stride (StreamStats) finishes its edges then; others
  // ignore it. Vertices not announced here are complete at finish().
  virtual void vertex_done(std::uint32_t vertex) { (void)vertex; }
  // Work on a block that need not wait for the sink's turn: called on any thread, for several
  // blocks at once, while the sink takes other calls, so it may read only what those never
  // change. None by default.
  virtual std::unique_ptr<SinkBlockWork> prepare(const SinkBlock& block) const {
    (void)block;
    return nullptr;
  }
  // The block, its vertices numbered from first_vertex and its groups from first_group, with
  // what prepare() gave for it: the same as vertex(), triangle() and vertex_done() in order,
  // which is what the default does.
  virtual void block(const SinkBlock& block, std::uint32_t first_vertex, std::uint32_t first_group,
                     std::unique_ptr<SinkBlockWork> work);
  // Every triangle has been given: those of group g are to be reversed where flip[g] != 0.
  virtual void finish(std::span<const std::uint8_t> flip) = 0;
};

}  // namespace g2s
