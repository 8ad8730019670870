// One thread of its own that runs one job at a time beside its owner: the owner starts a job,
// goes on, and waits for it only when it starts the next or needs its result. The write-behind
// of the output (io/write_behind.hpp) and the sink's thread (g2s/sink_behind.hpp) are built on it.
// The job keeps its own result or error; reading it after wait() (or after start(), which waits
// first) is ordered after the job by the handover's mutex.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

namespace g2s {

class JobThread {
 public:
  JobThread();
  ~JobThread();  // waits for the job in flight, then ends the thread
  JobThread(const JobThread&) = delete;
  JobThread& operator=(const JobThread&) = delete;

  // Waits until no job is in flight, then calls prepare() (on the owner's thread, the job's data
  // now free to touch) and starts `job`, unless prepare() returns false.
  template <class Prepare>
  void start(Prepare&& prepare, std::function<void()> job) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !busy_; });
    if (!prepare()) return;
    job_ = std::move(job);
    busy_ = true;
    lock.unlock();
    changed_.notify_all();
  }
  // Until no job is in flight.
  void wait();
  // CPU seconds the thread has used.
  double cpu_seconds() const { return 1e-9 * static_cast<double>(cpu_ns_.load()); }

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> job_;
  bool busy_ = false;
  bool stop_ = false;
  std::atomic<std::uint64_t> cpu_ns_{0};
  std::thread thread_;
};

}  // namespace g2s
