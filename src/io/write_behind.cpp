// WriteBehind (write_behind.hpp): one thread, one buffer in flight, handed over under a mutex.
#include "io/write_behind.hpp"

#include <time.h>
#include <unistd.h>

#include <cerrno>

namespace g2s {

WriteBehind::WriteBehind(int fd, std::size_t capacity) : fd_(fd) {
  pending_.reserve(capacity);
  thread_ = std::thread([this] { run(); });
}

WriteBehind::~WriteBehind() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

int WriteBehind::submit(std::vector<char>& buffer, std::uint64_t offset) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !busy_; });
  if (error_ != 0) return error_;
  pending_.swap(buffer);
  buffer.clear();
  offset_ = offset;
  busy_ = true;
  lock.unlock();
  changed_.notify_all();
  return 0;
}

int WriteBehind::wait() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !busy_; });
  return error_;
}

void WriteBehind::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return busy_ || stop_; });
    if (!busy_) return;
    lock.unlock();
    // The caller touches neither pending_ nor offset_ while busy_.
    int error = 0;
    const char* p = pending_.data();
    std::size_t left = pending_.size();
    std::uint64_t offset = offset_;
    while (left > 0) {
      const ssize_t n = ::pwrite(fd_, p, left, static_cast<off_t>(offset));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        error = n < 0 ? errno : EIO;
        break;
      }
      p += n;
      left -= static_cast<std::size_t>(n);
      offset += static_cast<std::uint64_t>(n);
    }
    pending_.clear();
    timespec cpu{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu);
    cpu_ns_ = static_cast<std::uint64_t>(cpu.tv_sec) * 1000000000u +
              static_cast<std::uint64_t>(cpu.tv_nsec);
    lock.lock();
    if (error_ == 0) error_ = error;
    busy_ = false;
    changed_.notify_all();
  }
}

}  // namespace g2s
