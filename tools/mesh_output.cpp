// The end of `g2s mesh` and `g2s stitch`: the mesh is streamed to the output as the stitcher
// finishes it, and its defects (g2s stats' counts on the written file) are counted on the way
// (StreamStats), so every run reports its own defects at little cost in time or memory. Only
// when that count could not be exact is the written mesh read back instead, if that fits in
// --memory.
#include "mesh_output.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/stats.hpp"
#include "g2s/stream_stats.hpp"
#include "g2s/surface_check.hpp"
#include "progress.hpp"

namespace g2s::cli {
namespace {

// Reading a mesh back and measuring it takes about this much per triangle (STL welding, the
// stats' edge map): `g2s stats` on the 20M-triangle torus STL peaked at 1.70 GB (85 bytes a
// triangle); twice that leaves room for meshes with more vertices per triangle.
constexpr std::uint64_t kStatsBytesPerTriangle = 160;

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

// Why a run gave no triangle: degenerate clouds by name, else too sparse.
[[noreturn]] void throw_no_surface(const TileSource& source, const PipelineSummary& summary,
                                   const RunFacts& facts) {
  PointCloud cloud;
  for (std::size_t t = 0; t < source.tiles().size(); ++t) {
    const TilePoints points = source.load(t);
    cloud.xyz.insert(cloud.xyz.end(), points.xyz.begin(), points.xyz.end());
  }
  std::string why = why_no_surface(cloud);
  if (why.empty()) {
    why = fmt::format("no triangle found among {} points (too sparse for --max-radius?)",
                      summary.report.points);
  }
  const std::string dropped =
      facts.non_finite > 0
          ? fmt::format(" ({} points with NaN or Inf coordinates dropped)", facts.non_finite)
          : "";
  throw Error(Exit::no_surface, fmt::format("{}: no surface can be formed: {}{}; nothing written",
                                            facts.input, why, dropped));
}

}  // namespace

void write_and_report(const TileSource& source,
                      const std::function<PipelineSummary(MeshSink&)>& run, const OutputArgs& args,
                      const RunFacts& facts) {
  const MeshFormat format = mesh_format_for(args.output, args.ascii);
  MeshStreamWriter writer(args.output, format);
  TimedFinish timed(writer);
  // STL stores float coordinates: the count welds and judges them as read back.
  StreamStats counter(timed, format != MeshFormat::ply_binary);
  const auto mesh_start = std::chrono::steady_clock::now();
  const double mesh_cpu = cpu_seconds();
  const PipelineSummary summary = args.no_stats ? run(timed) : run(static_cast<MeshSink&>(counter));
  const StageTime mesh{seconds_since(mesh_start), cpu_seconds() - mesh_cpu};
  if (summary.triangles == 0) throw_no_surface(source, summary, facts);
  if (!args.quiet && format != MeshFormat::ply_binary) {
    warn_if_stl_rounds(args.output, writer, summary.report.spacing);
  }
  const MeshReport& r = summary.report;
  const std::uint64_t triangles = summary.triangles;
  // The summary: counted in stride, or (should that count not be exact) read back when that
  // fits in the budget.
  const auto summary_start = std::chrono::steady_clock::now();
  const double summary_cpu = cpu_seconds();
  MeshStats stats;
  bool measure = false;
  // Far from the origin, STL's floats may merge vertices the stream saw apart (the warning
  // above): the file is then measured as read back.
  const bool stream_exact = counter.complete() && (format == MeshFormat::ply_binary ||
                                                   writer.float_rounding() <= 0.01 * r.spacing);
  if (!args.no_stats && stream_exact) {
    stats = counter.stats();
    measure = true;
  } else if (!args.no_stats &&
             (args.memory == 0 || triangles * kStatsBytesPerTriangle <= args.memory)) {
    stats = compute_stats(read_mesh(args.output));
    measure = true;
  }
  const StageTime measured{seconds_since(summary_start), cpu_seconds() - summary_cpu};
  const double seconds = seconds_since(facts.start);
  const double ktps = static_cast<double>(triangles) / seconds / 1000.0;
  const double peak_mb = peak_rss_mb();
  if (args.json) {
    fmt::print(
        "{{\"input\":\"{}\",\"output\":\"{}\",\"points\":{},\"non_finite\":{},\"ignored_bytes\":{},"
        "\"duplicates_merged\":{},\"spacing\":{},\"seeds\":{},\"triangles\":{},\"vertices\":{},"
        "\"triangles_removed\":{},\"tiles\":{},\"triangles_stitched\":{},"
        "\"seam_triangles_dropped\":{},\"vertices_unjudged\":{},\"peak_live_points\":{},"
        "\"seconds\":{:.3f},"
        "\"seconds_grid\":{:.3f},\"seconds_grow\":{:.3f},\"seconds_stitch\":{:.3f},"
        "\"seconds_cleanup\":{:.3f},\"ktriangles_per_second\":{:.1f},\"peak_rss_mb\":{:.1f},"
        "\"stages\":{{\"tile\":{{\"wall\":{:.3f},\"cpu\":{:.3f}}},"
        "\"grow_and_stitch\":{{\"wall\":{:.3f},\"cpu\":{:.3f}}},\"grow\":{{\"cpu\":{:.3f}}},"
        "\"stitch\":{{\"cpu\":{:.3f}}},"
        "\"output\":{{\"wall\":{:.3f},\"cpu\":{:.3f}}},"
        "\"summary\":{{\"wall\":{:.3f},\"cpu\":{:.3f},\"in_stride\":{}}}}}",
        facts.input, args.output, r.points, facts.non_finite, facts.ignored_bytes,
        r.duplicates_merged, r.spacing, r.seeds, triangles, summary.vertices, r.triangles_removed,
        summary.tiles, summary.triangles_stitched, summary.seam_triangles_dropped,
        summary.vertices_unjudged, summary.peak_live_points, seconds, r.seconds_grid,
        r.seconds_grow, summary.seconds_stitch, r.seconds_cleanup, ktps, peak_mb, facts.tile.wall,
        facts.tile.cpu, mesh.wall - timed.time.wall, mesh.cpu - timed.time.cpu,
        summary.cpu_seconds_grow, summary.cpu_seconds_stitch, timed.time.wall, timed.time.cpu,
        measured.wall, measured.cpu, measure && stream_exact && !args.no_stats ? "true" : "false");
    if (measure) fmt::print(",\"stats\":{}", stats_to_json(stats));
    fmt::print("}}\n");
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
               "components {}; crossings: run g2s stats",
               stats.non_manifold_edges, stats.non_manifold_vertices, stats.orientation_conflicts,
               stats.boundary_edges, stats.holes, stats.duplicate_triangles,
               stats.degenerate_triangles, stats.components);
  } else if (!args.no_stats) {
    fmt::print(stderr,
               "; defects not measured: reading the mesh back would exceed --memory "
               "(run g2s stats on it)");
  }
  fmt::print(stderr, "\n");
}

}  // namespace g2s::cli
