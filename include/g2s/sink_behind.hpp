// A sink that takes the stitcher's triangles one at a time (MeshSink::vertex, triangle,
// vertex_done) on a thread of its own. In `g2s mesh` (from 8 threads) the sink is the defect count
// (StreamStats) in front of the writer, and the triangles that leave the live mesh one by one reach
// it from the serial stitch stage: on the 20M-point torus, counting and encoding them was about a
// third of that stage's CPU. Here the stitch stage only copies each call into a batch, and full
// batches are played to the next sink on the other thread, in order, so the next sink sees the very
// calls it would have seen, one at a time. block() and finish() wait until every batch is played,
// then go to the next sink from the caller's thread; prepare() goes straight through (it may run
// beside the other calls anyway).
//
// Inputs: next, the sink to play the calls to. Outputs: the same calls to next, in the same order,
// never two at once. An exception thrown by next on the other thread is thrown again from the next
// call that hands over a batch, from block() or from finish(); after it, no more calls reach next.
// Memory: two batches of kBatchCalls calls, under 1 MB.

#pragma once

#include <cstdint>
#include <exception>
#include <memory>
#include <vector>

#include "g2s/mesh_sink.hpp"

namespace g2s {

class JobThread;

class SinkBehind final : public MeshSink {
 public:
  explicit SinkBehind(MeshSink& next);
  ~SinkBehind() override;  // waits for the batch in flight; calls not yet played are dropped
  SinkBehind(const SinkBehind&) = delete;
  SinkBehind& operator=(const SinkBehind&) = delete;

  void vertex(Index id, const double xyz[3]) override;
  void triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                std::uint32_t group) override;
  void vertex_done(std::uint32_t vertex) override;
  std::unique_ptr<SinkBlockWork> prepare(const SinkBlock& block) const override;
  void block(const SinkBlock& block, std::uint32_t first_vertex, std::uint32_t first_group,
             std::unique_ptr<SinkBlockWork> work) override;
  void finish(std::span<const std::uint8_t> flip) override;

  // CPU seconds the playing thread has used.
  double cpu_seconds() const;

  static constexpr std::size_t kBatchCalls = 4096;

 private:
  // One call, its positions copied (the caller's may be gone by the time it is played).
  struct Call {
    enum class Kind : std::uint8_t { vertex, triangle, vertex_done };
    Kind kind;
    std::uint32_t number;  // vertex: the point's id; vertex_done: the vertex; triangle: group
    Triangle corners;
    double xyz[9];
  };
  void hand_over();  // the filling batch to the thread, once it is free
  void wait_idle();  // until every batch handed over is played; throws what next threw
  void play();       // playing_ to next, on the thread

  MeshSink& next_;
  std::vector<Call> filling_;
  std::vector<Call> playing_;  // being played while a job is in flight, else the spare
  std::exception_ptr error_;
  std::unique_ptr<JobThread> thread_;  // last: it ends before the batches go
};

}  // namespace g2s
