// g2s: the command-line tool. A thin layer over include/g2s/: parse, call, report.
#include <fmt/core.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"

namespace {

// Page faults are a large part of a run on a virtual machine: about 10 us each on the 2-vCPU
// VM, where meshing the 5M-point torus on one thread took 365k of them. With glibc's
// transparent huge pages for malloc's memory (the tunable glibc.malloc.hugetlb=1, which glibc
// reads only at start-up) it took 14k and 25% less time (bench/results/2026-11-28-session21.md).
// So the tool starts itself once more with the tunable added, unless GLIBC_TUNABLES already
// names it (glibc.malloc.hugetlb=0 keeps it off), or valgrind runs it (its preload library is
// in LD_PRELOAD: valgrind does not follow the restart). Where it cannot (no /proc), it goes on.
void restart_with_huge_pages(char** argv) {
  constexpr const char* kTunable = "glibc.malloc.hugetlb";
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, kTunable) != nullptr) return;
  const char* preload = std::getenv("LD_PRELOAD");
  if (preload != nullptr && std::strstr(preload, "vgpreload") != nullptr) return;
  const std::string before = tunables != nullptr ? tunables : "";
  const std::string value = (before.empty() ? "" : before + ":") + kTunable + "=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  if (tunables != nullptr) {
    setenv("GLIBC_TUNABLES", before.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

}  // namespace

namespace g2s::cli {

// A fixed threshold: glibc's own raises it as blocks are freed and keeps a fragmented heap that
// grows with the run (+60% peak RSS at 40M points). At 1 MiB every tile-sized array was a fresh
// mapping, and its page faults (expensive on virtual machines) took a quarter of the run; at
// 32 MiB a tile's arrays are reused from the heap: 20-33% less wall time, peak +6-30%
// (bench/results/2026-11-27-heap-threshold.md). The same bound on the free space kept at the top
// of each heap: at glibc's 128 KiB, a freed tile's arrays went back to the kernel and came back
// as page faults for the next tile (15-28% less wall time on the shared scans). But each of the
// run's 3-4 heaps may then keep 32 MiB free, about 100 MB that a small budget does not have
// (alpe under --memory 256M peaked at 364-418 MB, 324-328 MB with either threshold at 4 MiB,
// bench/results/2026-11-28-session23.md): so at most a 64th of the budget.
void fit_heap_to_budget(std::uint64_t budget_bytes) {
  const auto threshold =
      static_cast<int>(std::clamp<std::uint64_t>(budget_bytes / 64, 128 << 10, 32 << 20));
  mallopt(M_MMAP_THRESHOLD, threshold);
  mallopt(M_TRIM_THRESHOLD, threshold);
}

// glibc gives each thread that allocates a heap of its own, in 4 KiB pages where the main heap
// has huge pages (restart_with_huge_pages): with 2 threads, lion took 8,048 page faults against
// 601 on one, and the work itself ran 5-10% slower. One heap for all: 2-thread wall time -7% on
// autzen and table-mug, -2% on lion, alpe within noise, system time halved; peaks +2-5% or less
// (bench/results/2026-12-06-session28.md). The threads allocate per tile and per
// seam, not in inner loops, so they seldom wait on its lock.
void one_heap_for_all_threads() {
  mallopt(M_ARENA_MAX, 1);
}

}  // namespace g2s::cli

int main(int argc, char** argv) {
  restart_with_huge_pages(argv);
  CLI::App app{
      "g2s: fast manifold surface reconstruction of point clouds (G2S mesh growing).\n\n"
      "Exit codes: 0 success; 1 internal error; 2 bad command line; 3 bad input (missing,\n"
      "unreadable or malformed file); 4 output could not be written (missing or read-only\n"
      "folder, disk full); 5 no surface: the points cannot form one (none usable, all the same,\n"
      "two distinct, all on one line, too sparse), nothing written; 130 interrupted."};
  g2s::install_interrupt_cleanup();
  g2s::cli::fit_heap_to_budget(std::uint64_t{1} << 40);
  g2s::cli::one_heap_for_all_threads();
  app.require_subcommand(1);
  app.failure_message(g2s::cli::failure_message);
  app.set_version_flag("--version", "g2s 0.1.0");
  g2s::cli::add_mesh_command(app);
  g2s::cli::add_stage_commands(app);
  g2s::cli::add_stats_command(app);
  g2s::cli::add_synth_command(app);
  g2s::cli::add_tile_commands(app);
  g2s::cli::add_render_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(g2s::Exit::usage);
  } catch (const g2s::Error& e) {
    fmt::print(stderr, "g2s: error: {}\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "g2s: error: out of memory\n");
    return static_cast<int>(g2s::Exit::failure);
  } catch (const std::exception& e) {
    fmt::print(stderr, "g2s: internal error: {}\n", e.what());
    return static_cast<int>(g2s::Exit::failure);
  }
  return 0;
}
