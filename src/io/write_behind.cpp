// WriteBehind (write_behind.hpp): each full buffer is one job of the JobThread.
#include "io/write_behind.hpp"

#include <unistd.h>

#include <cerrno>

namespace g2s {

WriteBehind::WriteBehind(int fd, std::size_t capacity) : fd_(fd) {
  pending_.reserve(capacity);
}

int WriteBehind::submit(std::vector<char>& buffer, std::uint64_t offset) {
  int error = 0;  // read while no write is in flight
  thread_.start(
      [&] {
        error = error_;
        if (error != 0) return false;
        pending_.swap(buffer);
        buffer.clear();
        offset_ = offset;
        return true;
      },
      [this] { write(); });
  return error;
}

int WriteBehind::wait() {
  thread_.wait();
  return error_;
}

void WriteBehind::write() {
  const char* p = pending_.data();
  std::size_t left = pending_.size();
  std::uint64_t offset = offset_;
  while (left > 0) {
    const ssize_t n = ::pwrite(fd_, p, left, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (error_ == 0) error_ = n < 0 ? errno : EIO;
      break;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
    offset += static_cast<std::uint64_t>(n);
  }
  pending_.clear();
}

}  // namespace g2s
