// The end of `g2s mesh` and `g2s stitch`: the mesh is written, then measured (g2s stats' counts)
// for the summary, so every run reports its own defects.
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

// STL holds 32-bit floats, whose step near 1e7 (georeferenced scans) is a metre: warn when that
// rounding moves vertices by more than a hundredth of the sampling spacing.
void warn_if_stl_rounds(const std::string& output, const std::vector<double>& xyz, double spacing) {
  double largest = 0.0, worst = 0.0;
  for (const double c : xyz) {
    largest = std::max(largest, std::abs(c));
    worst = std::max(worst, std::abs(c - static_cast<double>(static_cast<float>(c))));
  }
  if (worst > 0.01 * spacing) {
    fmt::print(stderr,
               "g2s: warning: {}: STL stores 32-bit floats, which round coordinates as large as "
               "{:.6g} by up to {:.3g} (the point spacing is {:.3g}); write .ply to keep them "
               "exactly\n",
               output, largest, worst, spacing);
  }
}

}  // namespace

void write_and_report(PipelineMesh& mesh, const OutputArgs& args, const RunFacts& facts) {
  if (mesh.triangles.empty()) {
    // Say why, from the positions the pipeline holds: degenerate clouds by name, else sparse.
    std::string why = why_no_surface(PointCloud{mesh.xyz});
    if (why.empty()) {
      why = fmt::format("no triangle found among {} points (too sparse for --max-radius?)",
                        mesh.report.points);
    }
    const std::string dropped =
        facts.non_finite > 0
            ? fmt::format(" ({} points with NaN or Inf coordinates dropped)", facts.non_finite)
            : "";
    throw Error(Exit::no_surface, fmt::format("{}: no surface can be formed: {}{}; nothing written",
                                              facts.input, why, dropped));
  }
  const MeshFormat format = mesh_format_for(args.output, args.ascii);
  if (!args.quiet && format != MeshFormat::ply_binary) {
    warn_if_stl_rounds(args.output, mesh.xyz, mesh.report.spacing);
  }
  write_mesh(args.output, mesh.xyz, mesh.triangles, format);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - facts.start).count();
  const MeshReport& r = mesh.report;
  const std::uint64_t triangles = mesh.triangles.size();
  const double ktps = static_cast<double>(triangles) / seconds / 1000.0;
  MeshStats stats;
  if (!args.no_stats) {
    IndexedMesh indexed{std::move(mesh.xyz), std::move(mesh.triangles)};
    stats = compute_stats(indexed);
  }
  if (args.json) {
    fmt::print(
        "{{\"input\":\"{}\",\"output\":\"{}\",\"points\":{},\"non_finite\":{},\"ignored_bytes\":{},"
        "\"duplicates_merged\":{},\"spacing\":{},\"seeds\":{},\"triangles\":{},"
        "\"triangles_removed\":{},\"tiles\":{},\"triangles_stitched\":{},\"seconds\":{:.3f},"
        "\"seconds_grid\":{:.3f},\"seconds_grow\":{:.3f},\"seconds_stitch\":{:.3f},"
        "\"seconds_cleanup\":{:.3f},\"ktriangles_per_second\":{:.1f},\"peak_rss_mb\":{:.1f}",
        facts.input, args.output, r.points, facts.non_finite, facts.ignored_bytes,
        r.duplicates_merged, r.spacing, r.seeds, triangles, r.triangles_removed, mesh.tiles,
        mesh.triangles_stitched, seconds, r.seconds_grid, r.seconds_grow, mesh.seconds_stitch,
        r.seconds_cleanup, ktps, peak_rss_mb());
    if (!args.no_stats) fmt::print(",\"stats\":{}", stats_to_json(stats));
    fmt::print("}}\n");
    return;
  }
  if (args.quiet) return;
  fmt::print(stderr,
             "{}: {} points, {} tiles -> {} triangles in {:.2f} s ({:.0f} k triangles/s), peak "
             "{:.0f} MB",
             args.output, r.points, mesh.tiles, triangles, seconds, ktps, peak_rss_mb());
  if (!args.no_stats) {
    fmt::print(stderr,
               "; non-manifold edges {}, non-manifold vertices {}, orientation conflicts {}, "
               "boundary edges {}, holes {}",
               stats.non_manifold_edges, stats.non_manifold_vertices, stats.orientation_conflicts,
               stats.boundary_edges, stats.holes);
  }
  fmt::print(stderr, "\n");
}

}  // namespace g2s::cli
