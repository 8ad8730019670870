// Stage 1 of the tiled pipeline: one tile grown with a halo of its neighbours' points. The halo
// lets G2S see across the tile's faces as if the cloud went on, so the triangles it keeps (those
// with every corner in the tile) are the ones the whole cloud would give there; triangles that
// reach into the halo are left to the seam stitcher. No triangle is kept by two tiles: its
// corners lie in one tile only.
//
// Points deeper inside the box than any seam reaches have their whole star here, so their
// non-manifold fans are cleaned here, in parallel, rather than by the serial stitcher; the
// points a deletion may split nearer the border go on to the stitcher as suspects. Triangles
// deeper still, beyond the stitcher's release margin too, are final: they come first, counted,
// and the stitcher passes them to the output without holding them.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <span>

#include "cleanup/cleanup.hpp"
#include "common/local_frame.hpp"
#include "common/seconds_since.hpp"
#include "g2s/tile_stages.hpp"
#include "grid/hash_grid.hpp"
#include "grow/crossings.hpp"
#include "grow/grower.hpp"
#include "stitch/seam_reach.hpp"

namespace g2s {
namespace {

// Judges the fans of the suspects deeper than `depth` (see above) and deletes the triangles of
// all but one fan; the suspects left, and those a deletion may have split, stay in second_fans.
// out.second_fans[0, halo_corners) are corners of triangles left out at the halo.
// point_depth: each point's depth in the tile (TileFaces::depth).
void clean_deep_fans(TileGrowth& out, std::span<const double> point_depth, double depth,
                     std::size_t halo_corners) {
  const std::size_t n = out.points.size();
  std::vector<std::uint8_t> deep(n, 0);
  for (std::size_t k = 0; k < n; ++k) deep[k] = point_depth[k] > depth;
  for (std::size_t k = 0; k < halo_corners; ++k) deep[out.second_fans[k]] = 0;
  std::vector<Index> judged, left;
  for (Index v : out.second_fans) (deep[v] ? judged : left).push_back(v);
  if (judged.empty()) return;
  std::vector<std::uint8_t> dead;
  const NonManifoldReport nm = mark_non_manifold_fans(out.triangles, n, judged, deep, dead, left);
  out.report.triangles_removed = nm.triangles_removed;
  out.report.non_manifold_vertices_fixed = nm.vertices_fixed;
  // Groups renumbered densely again, in order of first kept triangle: none is left empty.
  std::vector<std::uint32_t> dense(out.groups, kNoIndex);
  out.groups = 0;
  std::size_t kept = 0;
  for (std::size_t t = 0; t < out.triangles.size(); ++t) {
    if (dead[t]) continue;
    std::uint32_t& group = dense[out.group[t]];
    if (group == kNoIndex) group = out.groups++;
    out.triangles[kept] = out.triangles[t];
    out.group[kept] = group;
    ++kept;
  }
  out.triangles.resize(kept);
  out.group.resize(kept);
  out.second_fans = std::move(left);
}

// Moves the triangles whose corners all lie deeper than `depth` (out of reach of every seam and
// of the clean-up's release margin: final already) to the front, in order, and counts them, so
// that the stitcher hands them straight to the output.
void put_final_first(TileGrowth& out, std::span<const double> point_depth, double depth) {
  auto deep = [&](Index v) { return point_depth[v] > depth; };
  std::vector<Triangle> rest;
  std::vector<std::uint32_t> rest_group;
  std::size_t final_count = 0;
  for (std::size_t t = 0; t < out.triangles.size(); ++t) {
    const Triangle tri = out.triangles[t];
    if (deep(tri[0]) && deep(tri[1]) && deep(tri[2])) {
      out.triangles[final_count] = tri;
      out.group[final_count] = out.group[t];
      ++final_count;
    } else {
      rest.push_back(tri);
      rest_group.push_back(out.group[t]);
    }
  }
  std::copy(rest.begin(), rest.end(), out.triangles.begin() + final_count);
  std::copy(rest_group.begin(), rest_group.end(), out.group.begin() + final_count);
  out.final_triangles = final_count;
}

// The halo's width around `tile`: halo_spacings of the largest spacing around it.
double halo_width(std::span<const TileInfo> tiles, std::size_t tile,
                  const PipelineOptions& options) {
  const double first = options.halo_spacings * tiles[tile].spacing;
  return options.halo_spacings * local_spacing(tiles, tile, tiles_near(tiles, tile, first));
}

}  // namespace

TileGrowth grow_tile(const TileSource& source, std::size_t tile, const PipelineOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::span<const TileInfo> tiles = source.tiles();
  const TileBox& box = tiles[tile].box;
  const double halo = halo_width(tiles, tile, options);

  TilePoints points = source.load(tile);
  const std::size_t own = points.size();
  TileGrowth out;
  out.points = points;
  for (std::size_t j : tiles_near(tiles, tile, halo)) {
    const TilePoints border = source.load_border(j, halo);
    for (std::size_t k = 0; k < border.size(); ++k) {
      if (box_distance(box, &border.xyz[3 * k]) > halo) continue;
      points.ids.push_back(border.ids[k]);
      points.xyz.insert(points.xyz.end(), &border.xyz[3 * k], &border.xyz[3 * k + 3]);
    }
  }
  const LocalFrame frame = tile_frame(tiles[tile]);
  const std::vector<float> local = frame.convert(points.xyz);
  const HashGrid grid(local, points.ids, source.group_distance(), source.twin_distance());
  const std::vector<Vec3> exact =
      detail::output_positions(grid, points.xyz, frame.exact(points.xyz));
  out.report.points = own;
  out.report.spacing = grid.spacing();
  out.report.seconds_grid = seconds_since(start);
  const auto grow_start = std::chrono::steady_clock::now();
  MeshOptions mesh_options = options.mesh;
  mesh_options.progress = {};  // tiles grow in parallel; the pipeline reports per tile
  // Holes are filled here among the tile's own points (a filling of them lies in the box); the
  // seams fill those that reach across.
  std::vector<std::uint8_t> fillable(grid.size(), 0);
  for (std::uint32_t k = 0; k < grid.size(); ++k) {
    const std::uint32_t s = grid.source(k);
    fillable[k] = s < own;
  }
  GrowContext context;
  context.fillable = fillable;
  context.cloud_spacing = source.cloud_spacing();
  context.exact_positions = exact;
  context.exact_origin = frame.origin();
  GrowResult grown = grow_mesh(grid, mesh_options, context);
  fillable = std::vector<std::uint8_t>();
  out.report.seeds = grown.seeds;
  out.report.seconds_finish = grown.seconds_finish;

  // Per grid point: its index among the tile's points (which come first), or kNoIndex for a
  // halo point.
  std::vector<Index> point_of(grid.size(), kNoIndex);
  std::uint64_t mine_count = 0;
  for (std::uint32_t k = 0; k < grid.size(); ++k) {
    if (grid.source(k) < own) {
      point_of[k] = grid.source(k);
      ++mine_count;
    }
  }
  auto mine = [&](Index v) { return point_of[v] != kNoIndex; };
  // Exact duplicates lie in one tile; of twins, the one with the smaller id is kept in every grid.
  out.report.duplicates_merged = own - mine_count;
  // Dense group numbers in order of first kept triangle: the same on every run.
  std::vector<std::uint32_t> dense(grown.triangles.size(), kNoIndex);
  out.triangles.reserve(grown.triangles.size());
  out.group.reserve(grown.triangles.size());
  for (std::size_t t = 0; t < grown.triangles.size(); ++t) {
    Triangle tri = grown.triangles[t];
    if (!mine(tri[0]) || !mine(tri[1]) || !mine(tri[2])) {
      // Leaving out a triangle that reaches into the halo can split a kept corner's fan in two.
      for (Index v : tri) {
        if (mine(v)) out.second_fans.push_back(point_of[v]);
      }
      continue;
    }
    if (grown.flip[t]) std::swap(tri[1], tri[2]);
    std::uint32_t& group = dense[grown.group[t]];
    if (group == kNoIndex) group = out.groups++;
    out.triangles.push_back({point_of[tri[0]], point_of[tri[1]], point_of[tri[2]]});
    out.group.push_back(group);
  }
  // Corners of triangles left out at the halo are near the border: never judged here.
  const std::size_t halo_corners = out.second_fans.size();
  for (Index v : grown.second_fans) {
    if (mine(v)) out.second_fans.push_back(point_of[v]);
  }
  out.report.triangles_grown = out.triangles.size();
  // Everything is in `out` now: free the grower's arrays before the clean-up makes its own.
  grown = GrowResult();
  point_of = std::vector<Index>();
  dense = std::vector<std::uint32_t>();
  // Each point's depth, once for both (not at every corner of its triangles).
  const TileFaces faces = tile_faces(tiles, tile);
  std::vector<double> point_depth(out.points.size());
  for (std::size_t k = 0; k < point_depth.size(); ++k) {
    point_depth[k] = faces.depth(&out.points.xyz[3 * k]);
  }
  clean_deep_fans(out, point_depth, seam_depth(tiles, tile, options), halo_corners);
  put_final_first(out, point_depth, seam_depth(tiles, tile, options, true));
  out.report.seconds_grow = seconds_since(grow_start);
  return out;
}

std::vector<std::uint64_t> count_halo_points(const TileSource& source,
                                             const PipelineOptions& options) {
  const std::span<const TileInfo> tiles = source.tiles();
  std::vector<double> halo(tiles.size(), 0.0);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    if (tiles[t].points > 0) halo[t] = halo_width(tiles, t, options);
  }
  tbb::enumerable_thread_specific<std::vector<std::uint64_t>> counts(
      std::vector<std::uint64_t>(tiles.size(), 0));
  // Each tile's points go to the halos of the tiles near it, as grow_tile gathers them: only a
  // prefix of the tile's block (its border) can lie within a halo of another box.
  const auto give = [&](std::size_t j, std::vector<std::size_t>& takers) {
    takers.clear();
    double widest = 0;
    for (std::size_t t = 0; t < tiles.size(); ++t) {
      if (t != j && tiles[t].points > 0 && box_gap(tiles[t].box, tiles[j].box) <= halo[t]) {
        takers.push_back(t);
        widest = std::max(widest, halo[t]);
      }
    }
    if (takers.empty()) return;
    std::vector<std::uint64_t>& count = counts.local();
    const TilePoints border = source.load_border(j, widest);
    for (std::size_t k = 0; k < border.size(); ++k) {
      for (const std::size_t t : takers) {
        count[t] += box_distance(tiles[t].box, &border.xyz[3 * k]) <= halo[t];
      }
    }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tiles.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<std::size_t> takers;
                      for (std::size_t j = range.begin(); j < range.end(); ++j) {
                        if (tiles[j].points > 0) give(j, takers);
                      }
                    });
  std::vector<std::uint64_t> total(tiles.size(), 0);
  for (const std::vector<std::uint64_t>& local : counts) {
    for (std::size_t t = 0; t < total.size(); ++t) total[t] += local[t];
  }
  return total;
}

}  // namespace g2s
