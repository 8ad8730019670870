// scan_points_ahead (readers.hpp): the reader on a thread of its own, a few runs ahead of the
// thread that takes them. The tile store reads its input two to four times; on one thread,
// decoding a binary PLY took as long as what each pass does with the points (the 20M-point
// torus: 0.45 s of decoding beside 0.4 s of sampling, counting and spilling), so the two
// overlap here. The runs go into a ring of kRuns buffers, swapped in rather than copied (the
// copy was a fifth of the reader's time on that torus), and are taken in order: the sink sees
// the same runs as scan_points gives, and an error of the reader reaches the caller after the
// runs before it, as it would there.
#include <tbb/task_arena.h>

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "io/readers.hpp"

namespace g2s::io {
namespace {

// Runs decoded ahead: three, so that a run slower to use than the next is to decode does not
// stall the reader (4.5 MB of doubles for PLY and LAS runs).
constexpr std::size_t kRuns = 3;

// Thrown through the reader to stop it when the caller stops taking runs.
struct Stopped {};

}  // namespace

void scan_points_ahead(const std::filesystem::path& path, const PointSink& sink,
                       ReadReport& report) {
  if (tbb::this_task_arena::max_concurrency() < 2) {
    scan_points(path, sink, report);
    return;
  }
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<double> runs[kRuns];
  std::size_t filled = 0, taken = 0;  // runs decoded and runs used so far; the ring's ends
  bool done = false, stop = false;
  std::exception_ptr error;
  ReadReport read;
  // The reader runs in an arena of its own, one thread fewer than the caller's, so that a reader
  // that parses in parallel (text) keeps to the caller's thread count with the caller's thread
  // taking the runs. Not the caller's arena: there it could wait for a slot that a caller
  // blocked here holds.
  tbb::task_arena arena(std::max(1, tbb::this_task_arena::max_concurrency() - 1));
  std::thread reader([&] {
    try {
      arena.execute([&] {
        scan_runs(
            path,
            [&](std::vector<double>& xyz) {
              std::unique_lock lock(mutex);
              changed.wait(lock, [&] { return stop || filled - taken < kRuns; });
              if (stop) throw Stopped{};
              std::vector<double>& run = runs[filled % kRuns];
              lock.unlock();
              run.swap(xyz);  // the reader refills the slot's old vector
              lock.lock();
              ++filled;
              changed.notify_all();
            },
            read);
      });
    } catch (const Stopped&) {
    } catch (...) {
      error = std::current_exception();
    }
    const std::lock_guard lock(mutex);
    done = true;
    changed.notify_all();
  });
  try {
    for (;;) {
      std::unique_lock lock(mutex);
      changed.wait(lock, [&] { return filled > taken || done; });
      if (filled == taken) break;  // done, and every run taken
      const std::vector<double>& run = runs[taken % kRuns];
      lock.unlock();
      sink(run);
      lock.lock();
      ++taken;
      changed.notify_all();
    }
  } catch (...) {
    {
      const std::lock_guard lock(mutex);
      stop = true;
      changed.notify_all();
    }
    reader.join();
    throw;
  }
  reader.join();
  if (error) std::rethrow_exception(error);
  report = read;
}

}  // namespace g2s::io
