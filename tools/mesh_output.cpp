// The end of `g2s mesh` and `g2s stitch`: the mesh is written, then measured (g2s stats' counts)
// for the summary, so every run reports its own defects.
#include "mesh_output.hpp"

#include <fmt/core.h>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "g2s/stats.hpp"
#include "progress.hpp"

namespace g2s::cli {

void write_and_report(PipelineMesh& mesh, const OutputArgs& args, const RunFacts& facts) {
  if (mesh.triangles.empty()) {
    throw Error(Exit::bad_input,
                fmt::format("{}: no triangle could be formed from {} points (too few, collinear "
                            "or too sparse); nothing written",
                            facts.input, mesh.report.points));
  }
  write_mesh(args.output, mesh.xyz, mesh.triangles, mesh_format_for(args.output, args.ascii));
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
        "{{\"input\":\"{}\",\"output\":\"{}\",\"points\":{},\"non_finite\":{},"
        "\"duplicates_merged\":{},\"spacing\":{},\"seeds\":{},\"triangles\":{},"
        "\"triangles_removed\":{},\"tiles\":{},\"triangles_stitched\":{},\"seconds\":{:.3f},"
        "\"seconds_grid\":{:.3f},\"seconds_grow\":{:.3f},\"seconds_stitch\":{:.3f},"
        "\"seconds_cleanup\":{:.3f},\"ktriangles_per_second\":{:.1f},\"peak_rss_mb\":{:.1f}",
        facts.input, args.output, r.points, facts.non_finite, r.duplicates_merged, r.spacing,
        r.seeds, triangles, r.triangles_removed, mesh.tiles, mesh.triangles_stitched, seconds,
        r.seconds_grid, r.seconds_grow, mesh.seconds_stitch, r.seconds_cleanup, ktps,
        peak_rss_mb());
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
