// g2s: the command-line tool. A thin layer over include/g2s/: parse, call, report.
#include <fmt/core.h>
#include <malloc.h>

#include <exception>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "g2s: fast manifold surface reconstruction of point clouds (G2S mesh growing).\n\n"
      "Exit codes: 0 success; 1 internal error; 2 bad command line; 3 bad input (missing,\n"
      "unreadable or malformed file); 4 output could not be written (missing or read-only\n"
      "folder, disk full); 5 no surface: the points cannot form one (none usable, all the same,\n"
      "two distinct, all on one line, too sparse), nothing written; 130 interrupted."};
  g2s::install_interrupt_cleanup();
  // A fixed threshold: glibc's own raises it as blocks are freed and keeps a fragmented heap
  // that grows with the run (+60% peak RSS at 40M points). At 1 MiB every tile-sized array was
  // a fresh mapping, and its page faults (expensive on virtual machines) took a quarter of the
  // run; at 32 MiB a tile's arrays are reused from the heap: 20-33% less wall time, peak +6-30%,
  // still well under --memory (bench/results/2026-11-27-heap-threshold.md). The same bound on
  // the free space kept at the top of each heap: at glibc's 128 KiB, a freed tile's arrays went
  // back to the kernel and came back as page faults for the next tile (a quarter of the page
  // faults' cost again: 15-28% less wall time on the shared scans).
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 32 << 20);
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
