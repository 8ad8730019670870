// JobThread (job_thread.hpp): one job in flight, handed over under a mutex.
#include "common/job_thread.hpp"

#include <time.h>

namespace g2s {

JobThread::JobThread() : thread_([this] { run(); }) {}

JobThread::~JobThread() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void JobThread::wait() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !busy_; });
}

void JobThread::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return busy_ || stop_; });
    if (!busy_) return;
    lock.unlock();
    job_();  // the owner touches the job's data only while !busy_
    timespec cpu{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu);
    cpu_ns_ = static_cast<std::uint64_t>(cpu.tv_sec) * 1000000000u +
              static_cast<std::uint64_t>(cpu.tv_nsec);
    lock.lock();
    busy_ = false;
    changed_.notify_all();
  }
}

}  // namespace g2s
