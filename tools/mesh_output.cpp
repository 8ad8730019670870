// The end of `g2s mesh` and `g2s stitch`: the mesh is streamed to the output as the stitcher
// finishes it, and its defects (g2s stats' counts on the written file) are counted on the way
// (StreamStats), so every run reports its own defects at little cost in time or memory. Only
// when that count could not be exact is the written mesh read back instead, if that fits in
// --memory.
#include "mesh_output.hpp"

#include <fmt/core.h>
#include <signal.h>
#include <sys/stat.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "cli_checks.hpp"
#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/sink_behind.hpp"
#include "g2s/stats.hpp"
#include "g2s/stream_stats.hpp"
#include "g2s/surface_check.hpp"
#include "json_writer.hpp"
#include "progress.hpp"

namespace g2s::cli {
namespace {

// Threads from which the sink gets a thread of its own (SinkBehind). Growth takes 7 to 16 times
// the serial stitch stage's CPU on the runs measured (the 20M torus, alpe, raw-bunny), so the
// stitcher starts to bound a run from about 8 threads; below, the thread would cost its heap
// (the count's tables, 12 MB on table-mug) and save no time.
constexpr int kSinkThreadFrom = 8;

// Passes everything on and times the sink's finish (the output's last pass: flipped groups
// rewritten, the file renamed into place).
class TimedFinish final : public MeshSink {
 public:
  explicit TimedFinish(MeshSink& next) : next_(next) {}
  void vertex(Index id, const double xyz[3]) override { next_.vertex(id, xyz); }
  void triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                std::uint32_t group) override {
    next_.triangle(corners, xyz, group);
  }
  void vertex_done(std::uint32_t vertex) override { next_.vertex_done(vertex); }
  std::unique_ptr<SinkBlockWork> prepare(const SinkBlock& block) const override {
    return next_.prepare(block);
  }
  void block(const SinkBlock& block, std::uint32_t first_vertex, std::uint32_t first_group,
             std::unique_ptr<SinkBlockWork> work) override {
    next_.block(block, first_vertex, first_group, std::move(work));
  }
  void finish(std::span<const std::uint8_t> flip) override {
    const auto start = std::chrono::steady_clock::now();
    const double cpu = cpu_seconds();
    next_.finish(flip);
    time.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    time.cpu = cpu_seconds() - cpu;
  }
  StageTime time;

 private:
  MeshSink& next_;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// STL holds 32-bit floats, whose step near 1e7 (georeferenced scans) is a metre: warn when that
// rounding moves vertices by more than a hundredth of the sampling spacing.
void warn_if_stl_rounds(const std::string& output, const MeshStreamWriter& writer, double spacing) {
  if (writer.float_rounding() > 0.01 * spacing) {
    fmt::print(stderr,
               "g2s: warning: {}: STL stores 32-bit floats, which round coordinates as large as "
               "{:.6g} by up to {:.3g} (the point spacing is {:.3g}); write .ply to keep them "
               "exactly\n",
               output, writer.largest_coordinate(), writer.float_rounding(), spacing);
  }
}

// More points left out than this share of the cloud get a note. On the shared real scans
// (airborne lidar, photogrammetry, range and stereo scans) at most 2.3% are (4_6_crop), outliers
// and a layer's points off its one sheet. Far more means many outliers, or a region sampled so much
// more sparsely than its tile that the search does not reach across it (docs/algorithm.md §8),
// and the mesh does not show it.
constexpr double kLeftOutNote = 0.05;

// Notes how many input points are not vertices of the mesh (duplicates merged aside), when they
// are more than kLeftOutNote of them.
void note_points_left_out(const std::string& output, const PipelineSummary& summary) {
  const MeshReport& r = summary.report;
  const std::uint64_t distinct =
      r.points > r.duplicates_merged ? r.points - r.duplicates_merged : 0;
  if (distinct == 0 || summary.vertices >= distinct) return;
  const std::uint64_t left_out = distinct - summary.vertices;
  const double share = static_cast<double>(left_out) / static_cast<double>(distinct);
  if (share <= kLeftOutNote) return;
  fmt::print(stderr,
             "g2s: note: {}: {} of the {} distinct points ({:.1f}%) are not vertices of the mesh: "
             "outliers, or a region sampled far more sparsely than the points around it, which "
             "the search does not reach (g2s stats --points gives their distances to the mesh; "
             "smaller tiles, --tile-points, recover part of such a region)\n",
             output, left_out, distinct, 100.0 * share);
}

// Points farther from their tile's centre than float resolves at the tile's spacing: the mesher
// (float around each tile's centre) merges them. A reason, or "".
std::string why_tile_too_wide(const TileSource& source) {
  for (const TileInfo& t : source.tiles()) {
    double half_width = 0.0;
    for (int a = 0; a < 3; ++a)
      half_width = std::max(half_width, 0.5 * (t.points_box.hi[a] - t.points_box.lo[a]));
    const double step = half_width * std::numeric_limits<float>::epsilon();
    if (t.points > 1 && t.spacing > 0.0 && step > 0.1 * t.spacing) {
      return fmt::format(
          "the points of a tile spread {:.6g} from its centre, so the mesher's float coordinates "
          "step by {:.3g}, too coarse for the point spacing {:.3g}: points closer than that "
          "merge (a stray point far from the rest?)",
          half_width, step, t.spacing);
    }
  }
  return "";
}

// Why the points of `source` cannot form a surface (none, one point, two, a line, a tile too wide
// for float precision), or "". Sets
// `all_float` to whether every coordinate is exactly a float, read on the check's first pass
// over the points (a pass the check makes anyway).
std::string why_no_surface(const TileSource& source, bool& all_float) {
  all_float = true;
  bool first_pass = true;
  std::string why = g2s::why_no_surface(source.point_count(), [&](const PointRun& visit) {
    for (std::size_t t = 0; t < source.tiles().size(); ++t) {
      const TilePoints points = source.load(t);
      if (first_pass) {
        for (const double c : points.xyz) {
          all_float = all_float && static_cast<double>(static_cast<float>(c)) == c;
        }
      }
      visit(points.xyz);
    }
    first_pass = false;
  });
  // A tile the mesher's float frame cannot resolve (stray points scattered so that the split
  // could not cut them off) would merge its points and those its seams load: refused, whatever
  // the rest makes.
  if (std::string too_wide = why_tile_too_wide(source); !too_wide.empty()) return too_wide;
  if (why.empty()) return {};
  // Stray points far from the rest stretch the extent the check measures collinearity against
  // (a millionth of it); where the tiles have kept them apart (kStrayGap, no tile left too wide
  // for float), each tile is meshed in a float frame of its own. So a tile far narrower than the
  // cloud whose own points make a surface is enough.
  const auto widest = [](const TileBox& box) {
    return std::max({box.hi[0] - box.lo[0], box.hi[1] - box.lo[1], box.hi[2] - box.lo[2]});
  };
  TileBox all;  // of every tile's points
  bool any = false;
  for (const TileInfo& t : source.tiles()) {
    if (t.points == 0) continue;
    for (int a = 0; a < 3; ++a) {
      all.lo[a] = any ? std::min(all.lo[a], t.points_box.lo[a]) : t.points_box.lo[a];
      all.hi[a] = any ? std::max(all.hi[a], t.points_box.hi[a]) : t.points_box.hi[a];
    }
    any = true;
  }
  for (std::size_t t = 0; t < source.tiles().size(); ++t) {
    const TileInfo& tile = source.tiles()[t];
    if (tile.points < 3 || kStrayGap * widest(tile.points_box) > widest(all)) continue;
    const TilePoints points = source.load(t);
    const auto visit_tile = [&](const PointRun& visit) { visit(points.xyz); };
    if (g2s::why_no_surface(points.size(), visit_tile).empty()) return {};
  }
  return why;
}

[[noreturn]] void throw_no_surface(const std::string& why, const RunFacts& facts) {
  const std::string dropped =
      facts.non_finite > 0
          ? fmt::format(" ({} points with NaN or Inf coordinates dropped)", facts.non_finite)
          : "";
  throw Error(Exit::no_surface, fmt::format("{}: no surface can be formed: {}{}; nothing written",
                                            facts.input, why, dropped));
}

// Why a run gave no triangle: the tiles' precision, else too sparse.
[[noreturn]] void throw_no_triangle(const TileSource& source, const PipelineSummary& summary,
                                    const RunFacts& facts) {
  std::string why = why_tile_too_wide(source);
  if (why.empty()) {
    why = fmt::format("no triangle found among {} points (too sparse for --max-radius?)",
                      summary.report.points);
  }
  throw_no_surface(why, facts);
}

// Once the mesh is complete at its target (renamed into place inside the library), an interrupt
// must not claim that nothing was written. This handler replaces the library's for the run:
// while the target is not the new file (absent, or still the old file's inode) it hands over to
// the library's handler (temporaries removed, "no output written"); once it is, it removes the
// temporary store and says the file is complete but its defects were not measured (exit 130
// still: the run did not finish). Async-signal-safe: stat, unlink, write, _exit; the strings
// are composed before it is installed.
struct SignalState {
  struct sigaction library {};
  char target[4096] = {};
  char store[4096] = {};
  char message[4608] = {};
  std::size_t message_length = 0;
  bool had_old = false;
  dev_t old_dev = 0;
  ino_t old_ino = 0;
};
SignalState g_signal;

void on_signal_during_output(int signal) {
  struct stat st {};
  const bool written =
      ::stat(g_signal.target, &st) == 0 &&
      (!g_signal.had_old || st.st_dev != g_signal.old_dev || st.st_ino != g_signal.old_ino);
  if (!written) {
    g_signal.library.sa_handler(signal);
    return;
  }
  if (g_signal.store[0] != '\0') ::unlink(g_signal.store);
  [[maybe_unused]] const ssize_t n =
      ::write(STDERR_FILENO, g_signal.message, g_signal.message_length);
  ::_exit(static_cast<int>(Exit::interrupted));
}

void install_output_signal_handler(const std::string& output, const std::string& store) {
  if (output.size() >= sizeof g_signal.target || store.size() >= sizeof g_signal.store) return;
  output.copy(g_signal.target, output.size());
  store.copy(g_signal.store, store.size());
  const std::string message = fmt::format(
      "g2s: interrupted while measuring the mesh; {} is complete, its defects were not "
      "measured\n",
      output);
  g_signal.message_length = message.copy(g_signal.message, sizeof g_signal.message);
  struct stat st {};
  g_signal.had_old = ::stat(output.c_str(), &st) == 0;
  g_signal.old_dev = st.st_dev;
  g_signal.old_ino = st.st_ino;
  struct sigaction action {};
  action.sa_handler = on_signal_during_output;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, &g_signal.library);  // the same handler for every one of them
  for (const int signal : interrupt_signals()) {
    if (signal != SIGINT) ::sigaction(signal, &action, nullptr);
  }
}

}  // namespace

void write_and_report(const TileSource& source,
                      const std::function<PipelineSummary(MeshSink&)>& run, const OutputArgs& args,
                      const RunFacts& facts) {
  const MeshFormat format = checked_mesh_format(args.output, args.ascii);
  // A degenerate cloud is refused before meshing: the mesher would make slivers of it.
  bool all_float = false;
  if (const std::string why = why_no_surface(source, all_float); !why.empty()) {
    throw_no_surface(why, facts);
  }
  install_output_signal_handler(args.output, facts.temporary_store);
  MeshStreamWriter writer(args.output, format);
  TimedFinish timed(writer);
  // STL stores float coordinates: the count welds and judges them as read back. The vertices are
  // distinct input points (exact duplicates are merged), so they can share a stored position
  // only where STL rounds distinct doubles to one float.
  const bool rounded = format != MeshFormat::ply_binary;
  StreamStats counter(timed, rounded, !rounded || all_float);
  const auto mesh_start = std::chrono::steady_clock::now();
  const double mesh_cpu = cpu_seconds();
  // With many threads, the triangles the stitcher releases one by one are counted and encoded
  // on a thread of their own (SinkBehind), off the serial stitch stage, which then bounds the
  // run less. With few, growth bounds the run and the thread would only cost memory: the
  // count's tables would sit in that thread's own heap, apart from what the run frees.
  MeshSink& counted = args.no_stats ? static_cast<MeshSink&>(timed) : counter;
  std::optional<SinkBehind> behind;
  if (tbb::this_task_arena::max_concurrency() >= kSinkThreadFrom) behind.emplace(counted);
  const PipelineSummary summary = run(behind ? static_cast<MeshSink&>(*behind) : counted);
  const StageTime mesh{seconds_since(mesh_start), cpu_seconds() - mesh_cpu};
  if (summary.triangles == 0) throw_no_triangle(source, summary, facts);
  if (facts.output_written) facts.output_written();
  if (!args.quiet && format != MeshFormat::ply_binary) {
    warn_if_stl_rounds(args.output, writer, summary.report.spacing);
  }
  if (!args.quiet) note_points_left_out(args.output, summary);
  const MeshReport& r = summary.report;
  const std::uint64_t triangles = summary.triangles;
  // The summary: counted in stride, or (should that count not be exact) read back when that
  // fits in the budget.
  const auto summary_start = std::chrono::steady_clock::now();
  const double summary_cpu = cpu_seconds();
  // Far from the origin, STL's floats may merge vertices the stream saw apart (the warning
  // above): the file is then measured as read back.
  const WrittenMeshStats written =
      args.no_stats ? WrittenMeshStats{}
                    : measure_written_mesh(counter, args.output, rounded, writer.float_rounding(),
                                           r.spacing, triangles, args.memory);
  const bool measure = written.stats.has_value();
  const MeshStats stats = written.stats.value_or(MeshStats{});
  const StageTime measured{seconds_since(summary_start), cpu_seconds() - summary_cpu};
  const double seconds = seconds_since(facts.start);
  const double ktps = static_cast<double>(triangles) / seconds / 1000.0;
  // Taken after the summary, so that it holds the counter (all along the run) and any
  // read-back; the counter's own share is reported apart.
  const double peak_mb = peak_rss_mb();
  const double counter_mb =
      args.no_stats ? 0.0 : static_cast<double>(counter.peak_bytes()) / (1024.0 * 1024.0);
  if (args.json) {
    JsonObject json;
    json.text("input", facts.input)
        .text("output", args.output)
        .number("points", r.points)
        .number("non_finite", facts.non_finite)
        .number("ignored_bytes", facts.ignored_bytes)
        .number("duplicates_merged", r.duplicates_merged)
        .number("spacing", r.spacing)
        .number("seeds", r.seeds)
        .number("triangles", triangles)
        .number("vertices", summary.vertices)
        .number("triangles_removed", r.triangles_removed)
        .number("tiles", summary.tiles)
        .number("triangles_stitched", summary.triangles_stitched)
        .number("seam_triangles_dropped", summary.seam_triangles_dropped)
        .number("vertices_unjudged", summary.vertices_unjudged)
        .number("peak_live_points", summary.peak_live_points)
        .fixed("seconds", seconds, 3)
        .fixed("seconds_grid", r.seconds_grid, 3)
        .fixed("seconds_grow", r.seconds_grow, 3)
        .fixed("seconds_finish", r.seconds_finish, 3)
        .fixed("seconds_stitch", summary.seconds_stitch, 3)
        .fixed("seconds_cleanup", r.seconds_cleanup, 3)
        .fixed("ktriangles_per_second", ktps, 1)
        .fixed("peak_rss_mb", peak_mb, 1);
    const auto stage = [](const StageTime& t) {
      return JsonObject().fixed("wall", t.wall, 3).fixed("cpu", t.cpu, 3).str();
    };
    json.raw(
        "stages",
        JsonObject()
            .raw("tile", stage(facts.tile))
            .raw("grow_and_stitch", stage({mesh.wall - timed.time.wall, mesh.cpu - timed.time.cpu}))
            .raw("grow", JsonObject().fixed("cpu", summary.cpu_seconds_grow, 3).str())
            .raw("stitch", JsonObject().fixed("cpu", summary.cpu_seconds_stitch, 3).str())
            .raw("sink", JsonObject().fixed("cpu", behind ? behind->cpu_seconds() : 0.0, 3).str())
            .raw("write", JsonObject().fixed("cpu", writer.write_cpu_seconds(), 3).str())
            .raw("output", stage(timed.time))
            .raw("summary", JsonObject()
                                .fixed("wall", measured.wall, 3)
                                .fixed("cpu", measured.cpu, 3)
                                .number("in_stride", written.in_stride)
                                .fixed("counter_peak_mb", counter_mb, 1)
                                .str())
            .str());
    if (measure) json.raw("stats", stats_to_json(stats));
    fmt::print("{}\n", json.str());
    return;
  }
  if (args.quiet) return;
  fmt::print(stderr,
             "{}: {} points, {} tiles -> {} triangles in {:.2f} s ({:.0f} k triangles/s), peak "
             "{:.0f} MB",
             args.output, r.points, summary.tiles, triangles, seconds, ktps, peak_mb);
  if (measure) {
    fmt::print(stderr,
               "; non-manifold edges {}, non-manifold vertices {}, orientation conflicts {}, "
               "boundary edges {}, holes {}, duplicate triangles {}, degenerate triangles {}, "
               "components {}, crossing triangle pairs {}",
               stats.non_manifold_edges, stats.non_manifold_vertices, stats.orientation_conflicts,
               stats.boundary_edges, stats.holes, stats.duplicate_triangles,
               stats.degenerate_triangles, stats.components,
               written.in_stride ? std::string("not counted here (g2s stats counts them)")
                                 : std::to_string(stats.crossing_pairs));
  } else if (!args.no_stats) {
    fmt::print(stderr,
               "; defects not measured: reading the mesh back would exceed --memory "
               "(run g2s stats on it)");
  }
  fmt::print(stderr, "\n");
}

}  // namespace g2s::cli
