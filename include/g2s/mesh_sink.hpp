// Where the tiled pipeline hands its mesh: a triangle at a time, as soon as nothing more can
// change it, so the whole mesh never has to be in memory. Only the orientation is decided at
// the end, for whole orientation groups at once (a group's triangles face one way).
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "g2s/types.hpp"

namespace g2s {

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
  // Every triangle has been given: those of group g are to be reversed where flip[g] != 0.
  virtual void finish(std::span<const std::uint8_t> flip) = 0;
};

}  // namespace g2s
