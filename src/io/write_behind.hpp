// Write-behind: full buffers go to a file on a thread of their own, so that the thread filling
// them does not also pay for the kernel's copy into the page cache. In `g2s mesh` the mesh's
// STL is filled by the serial stitcher; on the 20M-point torus, writing its 2 GB was 5.7% of the
// run's CPU, all of it on that one thread. Two buffers: the caller fills one while the other is
// written, and waits only when it has filled its own first. Each buffer is written at the offset
// given with it (pwrite), so the file position plays no part.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/job_thread.hpp"

namespace g2s {

class WriteBehind {
 public:
  // Inputs: an open file, and the capacity of the buffers the caller fills (the spare one is
  // reserved to it, so handing buffers back and forth never reallocates).
  WriteBehind(int fd, std::size_t capacity);
  ~WriteBehind() = default;  // waits for the write in flight; its error, if any, is dropped
  WriteBehind(const WriteBehind&) = delete;
  WriteBehind& operator=(const WriteBehind&) = delete;

  // Waits for the write in flight, then hands `buffer` over to be written at `offset`, leaving
  // an empty buffer of the same capacity in its place. Returns 0, or the errno of a write that
  // failed before (then `buffer` is kept and nothing more is written).
  int submit(std::vector<char>& buffer, std::uint64_t offset);
  // Waits until every buffer handed over is written. Returns 0, or the errno of the first
  // write that failed.
  int wait();
  // CPU seconds the writing thread has used.
  double cpu_seconds() const { return thread_.cpu_seconds(); }

 private:
  void write();  // pending_ at offset_, on the thread

  int fd_;
  std::vector<char> pending_;  // being written while a job is in flight, else the spare
  std::uint64_t offset_ = 0;
  int error_ = 0;
  JobThread thread_;  // last: it ends before the buffers go
};

}  // namespace g2s
