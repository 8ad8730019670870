// SinkBehind (g2s/sink_behind.hpp): each full batch is one job of a JobThread, as the output's
// buffers are in io/write_behind.
#include "g2s/sink_behind.hpp"

#include <algorithm>

#include "common/job_thread.hpp"

namespace g2s {

SinkBehind::SinkBehind(MeshSink& next) : next_(next), thread_(std::make_unique<JobThread>()) {
  filling_.reserve(kBatchCalls);
  playing_.reserve(kBatchCalls);
}

SinkBehind::~SinkBehind() = default;

double SinkBehind::cpu_seconds() const {
  return thread_->cpu_seconds();
}

void SinkBehind::vertex(Index id, const double xyz[3]) {
  Call& call = filling_.emplace_back();
  call.kind = Call::Kind::vertex;
  call.number = id;
  std::copy(xyz, xyz + 3, call.xyz);
  if (filling_.size() == kBatchCalls) hand_over();
}

void SinkBehind::triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                          std::uint32_t group) {
  Call& call = filling_.emplace_back();
  call.kind = Call::Kind::triangle;
  call.number = group;
  call.corners = corners;
  for (int k = 0; k < 3; ++k) std::copy(xyz[k], xyz[k] + 3, call.xyz + 3 * k);
  if (filling_.size() == kBatchCalls) hand_over();
}

void SinkBehind::vertex_done(std::uint32_t vertex) {
  Call& call = filling_.emplace_back();
  call.kind = Call::Kind::vertex_done;
  call.number = vertex;
  if (filling_.size() == kBatchCalls) hand_over();
}

std::unique_ptr<SinkBlockWork> SinkBehind::prepare(const SinkBlock& block) const {
  return next_.prepare(block);
}

void SinkBehind::block(const SinkBlock& block, std::uint32_t first_vertex,
                       std::uint32_t first_group, std::unique_ptr<SinkBlockWork> work) {
  hand_over();
  wait_idle();
  next_.block(block, first_vertex, first_group, std::move(work));
}

void SinkBehind::finish(std::span<const std::uint8_t> flip) {
  hand_over();
  wait_idle();
  next_.finish(flip);
}

void SinkBehind::hand_over() {
  std::exception_ptr error;  // read while no batch is in flight
  thread_->start(
      [&] {
        error = error_;
        if (error || filling_.empty()) return false;
        playing_.swap(filling_);
        filling_.clear();
        return true;
      },
      [this] { play(); });
  if (error) std::rethrow_exception(error);
}

void SinkBehind::wait_idle() {
  thread_->wait();
  if (error_) std::rethrow_exception(error_);
}

void SinkBehind::play() {
  try {
    for (const Call& call : playing_) {
      switch (call.kind) {
        case Call::Kind::vertex:
          next_.vertex(call.number, call.xyz);
          break;
        case Call::Kind::triangle:
          next_.triangle(call.corners, {call.xyz, call.xyz + 3, call.xyz + 6}, call.number);
          break;
        case Call::Kind::vertex_done:
          next_.vertex_done(call.number);
          break;
      }
    }
  } catch (...) {
    error_ = std::current_exception();  // the owner reads it only while no batch is in flight
  }
  playing_.clear();
}

}  // namespace g2s
