// The end of `g2s mesh` and `g2s stitch`: the mesh is streamed to the output as the stitcher
// finishes it, then read back and measured (g2s stats' counts) for the summary, so every run
// reports its own defects (unless that read-back would not fit in --memory).
#include "mesh_output.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/stats.hpp"
#include "g2s/surface_check.hpp"
#include "progress.hpp"

namespace g2s::cli {
namespace {

// Reading a mesh back and measuring it takes about this much per triangle (STL welding, the
// stats' edge map): `g2s stats` on the 20M-triangle torus STL peaked at 1.70 GB (85 bytes a
// triangle); twice that leaves room for meshes with more vertices per triangle.
constexpr std::uint64_t kStatsBytesPerTriangle = 160;

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
  const PipelineSummary summary = run(writer);
  if (summary.triangles == 0) throw_no_surface(source, summary, facts);
  if (!args.quiet && format != MeshFormat::ply_binary) {
    warn_if_stl_rounds(args.output, writer, summary.report.spacing);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - facts.start).count();
  const MeshReport& r = summary.report;
  const std::uint64_t triangles = summary.triangles;
  const double ktps = static_cast<double>(triangles) / seconds / 1000.0;
  const double peak_mb = peak_rss_mb();
  const bool measure =
      !args.no_stats && (args.memory == 0 || triangles * kStatsBytesPerTriangle <= args.memory);
  MeshStats stats;
  if (measure) stats = compute_stats(read_mesh(args.output));
  if (args.json) {
    fmt::print(
        "{{\"input\":\"{}\",\"output\":\"{}\",\"points\":{},\"non_finite\":{},\"ignored_bytes\":{},"
        "\"duplicates_merged\":{},\"spacing\":{},\"seeds\":{},\"triangles\":{},\"vertices\":{},"
        "\"triangles_removed\":{},\"tiles\":{},\"triangles_stitched\":{},"
        "\"seam_triangles_dropped\":{},\"vertices_unjudged\":{},\"peak_live_points\":{},"
        "\"seconds\":{:.3f},"
        "\"seconds_grid\":{:.3f},\"seconds_grow\":{:.3f},\"seconds_stitch\":{:.3f},"
        "\"seconds_cleanup\":{:.3f},\"ktriangles_per_second\":{:.1f},\"peak_rss_mb\":{:.1f}",
        facts.input, args.output, r.points, facts.non_finite, facts.ignored_bytes,
        r.duplicates_merged, r.spacing, r.seeds, triangles, summary.vertices, r.triangles_removed,
        summary.tiles, summary.triangles_stitched, summary.seam_triangles_dropped,
        summary.vertices_unjudged, summary.peak_live_points, seconds, r.seconds_grid,
        r.seconds_grow, summary.seconds_stitch, r.seconds_cleanup, ktps, peak_mb);
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
               "boundary edges {}, holes {}, crossing triangle pairs {}",
               stats.non_manifold_edges, stats.non_manifold_vertices, stats.orientation_conflicts,
               stats.boundary_edges, stats.holes, stats.crossing_pairs);
  } else if (!args.no_stats) {
    fmt::print(stderr,
               "; defects not measured: reading the mesh back would exceed --memory "
               "(run g2s stats on it)");
  }
  fmt::print(stderr, "\n");
}

}  // namespace g2s::cli
