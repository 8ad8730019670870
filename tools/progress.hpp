// Shared by the subcommands: the one-line progress bar on a terminal and the peak memory for
// the summary line.
#pragma once

#include <fmt/core.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace g2s::cli {

// The process's own peak resident memory: VmHWM of /proc/self/status. Not ru_maxrss, which Linux
// carries over exec from the process that started g2s (a Python or a test process holding
// hundreds of megabytes would be reported as g2s's peak); ru_maxrss only where /proc is missing.
inline double peak_rss_mb() {
  if (std::FILE* status = std::fopen("/proc/self/status", "r")) {
    char line[256];
    double kib = -1;
    while (std::fgets(line, sizeof line, status)) {
      if (std::sscanf(line, "VmHWM: %lf kB", &kib) == 1) break;
    }
    std::fclose(status);
    if (kib >= 0) return kib / 1024.0;
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// CPU seconds the process has used so far, user and system, over all its threads.
inline double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// A stage's wall and CPU seconds (the CPU of all threads).
struct StageTime {
  double wall = 0.0;
  double cpu = 0.0;
};

// A one-line progress bar on stderr, redrawn in place; only when stderr is a terminal.
class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}
  void stage(const char* name, double fraction) {
    if (!enabled_) return;
    const int width = 30;
    const int done = static_cast<int>(std::lround(fraction * width));
    fmt::print(stderr, "\r{:<10} [{:<{}}] {:3.0f}%", name, std::string(done, '#'), width,
               fraction * 100);
    std::fflush(stderr);
  }
  void clear() {
    if (enabled_) fmt::print(stderr, "\r{:60}\r", "");
  }

 private:
  bool enabled_;
};

}  // namespace g2s::cli
