// SinkBehind (g2s/sink_behind.hpp): one thread, one batch in flight, handed over under a mutex,
// as io/write_behind does with buffers.
#include "g2s/sink_behind.hpp"

#include <time.h>

#include <algorithm>

namespace g2s {

SinkBehind::SinkBehind(MeshSink& next) : next_(next) {
  filling_.reserve(kBatchCalls);
  playing_.reserve(kBatchCalls);
  thread_ = std::thread([this] { run(); });
}

SinkBehind::~SinkBehind() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
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
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !busy_; });
  if (error_) std::rethrow_exception(error_);
  if (filling_.empty()) return;
  playing_.swap(filling_);
  filling_.clear();
  busy_ = true;
  lock.unlock();
  changed_.notify_all();
}

void SinkBehind::wait_idle() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !busy_; });
  if (error_) std::rethrow_exception(error_);
}

void SinkBehind::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return busy_ || stop_; });
    if (!busy_) return;
    lock.unlock();
    // The caller touches playing_ only while !busy_.
    std::exception_ptr error;
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
      error = std::current_exception();
    }
    playing_.clear();
    timespec cpu{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu);
    cpu_ns_ = static_cast<std::uint64_t>(cpu.tv_sec) * 1000000000u +
              static_cast<std::uint64_t>(cpu.tv_nsec);
    lock.lock();
    if (!error_) error_ = error;
    busy_ = false;
    changed_.notify_all();
  }
}

}  // namespace g2s
