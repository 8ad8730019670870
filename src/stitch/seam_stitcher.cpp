// Stage 2 of the tiled pipeline: the seam stitcher (ALGORITHM.md §7.3). Tiles keep only the
// triangles with every corner inside them, so a strip of triangles across each seam is missing.
// Tiles are visited in index order; at tile i the seams with its already visited neighbours are
// closed by growing G2S over the points within the band width of those seams, with every
// triangle kept so far that touches those points loaded into the Point-Edge Map: their open
// edges are the front, and no new triangle can give an edge a third triangle or a vertex a
// crossing fan the clean-up cannot see. Points farther out are loaded as context, so the Gabriel
// test sees the whole neighbourhood, but are not used.
//
// Orientation: every kept triangle belongs to an orientation group (from its tile or seam); the
// stitcher joins groups with a parity as it connects them, and the end flips each group so that
// all of a component faces one way, then orients the component as the in-memory mesher does.
#include <algorithm>
#include <chrono>
#include <numeric>

#include "cleanup/cleanup.hpp"
#include "common/union_find.hpp"
#include "g2s/error.hpp"
#include "g2s/pipeline.hpp"
#include "grid/hash_grid.hpp"
#include "grow/grower.hpp"
#include "pipeline/tile_geometry.hpp"

namespace g2s {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Everything kept so far, in global ids, with each triangle's orientation group.
struct KeptMesh {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> group;
  ParityUnionFind groups;
  std::vector<Index> second_fans;
};

class SeamStitcher {
 public:
  SeamStitcher(const TileSource& source, const PipelineOptions& options, std::size_t ids)
      : source_(source), options_(options), in_band_(ids, 0), loaded_(ids, 0) {}

  // Closes the seams between `tile` and its neighbours with smaller indices. xyz: every point's
  // position by global id.
  std::uint64_t stitch(std::size_t tile, const std::vector<double>& xyz, KeptMesh& kept) {
    const std::span<const TileInfo> tiles = source_.tiles();
    const TileBox& box = tiles[tile].box;
    const double reach0 = 2 * options_.band_spacings * tiles[tile].spacing;
    const std::vector<std::size_t> near0 = tiles_near(tiles, tile, reach0);
    const double spacing = local_spacing(tiles, tile, near0);
    const double band = options_.band_spacings * spacing;
    const double reach = 2 * band;  // the band and the context around it
    const std::vector<std::size_t> near = tiles_near(tiles, tile, reach);
    std::vector<std::size_t> earlier;
    for (std::size_t j : near) {
      if (j < tile) earlier.push_back(j);
    }
    if (earlier.empty()) return 0;

    // The band (growable) and its context, from the tile and its neighbours' borders.
    ids_.clear();
    auto take = [&](Index id, bool growable) {
      if (loaded_[id]) return;
      loaded_[id] = 1;
      in_band_[id] = growable;
      ids_.push_back(id);
    };
    {
      const TilePoints own = source_.load_border(tile, reach);
      for (std::size_t k = 0; k < own.size(); ++k) {
        double d = reach + 1;
        for (std::size_t j : earlier) d = std::min(d, box_distance(tiles[j].box, &own.xyz[3 * k]));
        if (d <= reach) take(own.ids[k], d <= band);
      }
    }
    for (std::size_t j : near) {
      const TilePoints border = source_.load_border(j, reach);
      for (std::size_t k = 0; k < border.size(); ++k) {
        const double d = box_distance(box, &border.xyz[3 * k]);
        if (d <= reach) take(border.ids[k], j < tile && d <= band);
      }
    }
    // Every kept triangle touching the band, presented facing as its group currently does, so
    // the grower starts from what earlier seams already decided.
    preload_.clear();
    preload_group_.clear();
    for (std::uint32_t t = 0; t < kept.triangles.size(); ++t) {
      const Triangle& tri = kept.triangles[t];
      if (!in_band_[tri[0]] && !in_band_[tri[1]] && !in_band_[tri[2]]) continue;
      const auto [root, parity] = kept.groups.find(kept.group[t]);
      preload_.push_back(parity ? Triangle{tri[0], tri[2], tri[1]} : tri);
      preload_group_.push_back(root);
      for (Index v : tri) take(v, in_band_[v]);
    }

    std::vector<float> local(3 * ids_.size());
    for (std::size_t k = 0; k < ids_.size(); ++k) {
      for (int a = 0; a < 3; ++a) {
        local[3 * k + a] =
            static_cast<float>(xyz[3 * std::size_t{ids_[k]} + a] - 0.5 * (box.lo[a] + box.hi[a]));
      }
    }
    const HashGrid grid(local, ids_);
    // Global id -> grid index for the preloaded corners (the grid keeps the smallest id of exact
    // duplicates, as every tile's grid does, so all kept corners are in it).
    std::vector<std::pair<Index, std::uint32_t>> index(grid.size());
    for (std::uint32_t k = 0; k < grid.size(); ++k) index[k] = {grid.id(k), k};
    std::sort(index.begin(), index.end());
    auto grid_index = [&](Index id) {
      const auto at = std::lower_bound(index.begin(), index.end(), std::pair{id, 0u});
      if (at == index.end() || at->first != id) {
        throw Error(Exit::failure, "seam stitcher: a kept corner is missing from the seam grid");
      }
      return at->second;
    };
    for (Triangle& t : preload_) {
      for (Index& v : t) v = grid_index(v);
    }
    std::vector<std::uint8_t> growable(grid.size());
    for (std::uint32_t k = 0; k < grid.size(); ++k) growable[k] = in_band_[grid.id(k)];

    MeshOptions mesh_options = options_.mesh;
    mesh_options.progress = {};
    GrowResult grown = grow_mesh(grid, mesh_options,
                                 {preload_, preload_group_, growable, options_.stitch_retries});

    // Orientation: per grower group, the first preloaded triangle anchors it to a kept group.
    const std::size_t preloaded = preload_.size();
    std::vector<std::pair<std::uint32_t, std::uint32_t>> anchor;  // grower group -> preload k
    std::vector<std::uint32_t> group_ids(grown.group.begin(), grown.group.end());
    std::sort(group_ids.begin(), group_ids.end());
    group_ids.erase(std::unique(group_ids.begin(), group_ids.end()), group_ids.end());
    std::vector<std::uint32_t> anchor_of(group_ids.size(), kNoIndex);
    auto slot = [&](std::uint32_t g) {
      return static_cast<std::size_t>(std::lower_bound(group_ids.begin(), group_ids.end(), g) -
                                      group_ids.begin());
    };
    for (std::uint32_t k = 0; k < preloaded; ++k) {
      std::uint32_t& a = anchor_of[slot(grown.group[k])];
      if (a == kNoIndex) {
        a = k;
        continue;
      }
      kept.groups.unite(preload_group_[a], preload_group_[k],
                        static_cast<std::uint8_t>(grown.flip[k] ^ grown.flip[a]));
    }
    std::vector<std::uint32_t> fresh(group_ids.size(), kNoIndex);  // groups with no anchor
    for (std::size_t k = 0; k < grown.triangles.size(); ++k) {
      const std::size_t s = slot(grown.group[preloaded + k]);
      std::uint8_t flip = grown.flip[preloaded + k];
      std::uint32_t group = 0;
      if (anchor_of[s] != kNoIndex) {
        flip ^= grown.flip[anchor_of[s]];
        group = preload_group_[anchor_of[s]];
      } else {
        if (fresh[s] == kNoIndex) fresh[s] = kept.groups.add();
        group = fresh[s];
      }
      Triangle t = grown.triangles[k];
      if (flip) std::swap(t[1], t[2]);
      kept.triangles.push_back({grid.id(t[0]), grid.id(t[1]), grid.id(t[2])});
      kept.group.push_back(group);
    }
    for (Index v : grown.second_fans) kept.second_fans.push_back(grid.id(v));

    for (Index id : ids_) loaded_[id] = in_band_[id] = 0;
    return grown.triangles.size();
  }

 private:
  const TileSource& source_;
  const PipelineOptions& options_;
  std::vector<std::uint8_t> in_band_;  // by global id, for the points of the current seam
  std::vector<std::uint8_t> loaded_;
  std::vector<Index> ids_;
  std::vector<Triangle> preload_;
  std::vector<std::uint32_t> preload_group_;
};

}  // namespace

PipelineMesh stitch_tiles(const TileSource& source, std::vector<TileGrowth> growths,
                          const PipelineOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::span<const TileInfo> tiles = source.tiles();
  if (growths.size() != tiles.size()) throw Error(Exit::failure, "stitch: one growth per tile");
  PipelineMesh out;
  out.tiles = tiles.size();
  const std::uint64_t n = source.point_count();
  if (n > kNoIndex) throw Error(Exit::bad_input, "cloud has more than 4,294,967,295 points");
  out.xyz.assign(3 * n, 0.0);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const TilePoints points = source.load(t);
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (points.ids[k] >= n)
        throw Error(Exit::bad_input, "tile store: a point id is out of range");
      std::copy_n(&points.xyz[3 * k], 3, &out.xyz[3 * std::size_t{points.ids[k]}]);
    }
  }

  KeptMesh kept;
  for (TileGrowth& g : growths) {
    const auto base = static_cast<std::uint32_t>(kept.groups.size());
    for (std::uint32_t k = 0; k < g.groups; ++k) kept.groups.add();
    kept.triangles.insert(kept.triangles.end(), g.triangles.begin(), g.triangles.end());
    for (std::uint32_t group : g.group) kept.group.push_back(base + group);
    kept.second_fans.insert(kept.second_fans.end(), g.second_fans.begin(), g.second_fans.end());
    out.report.points += g.report.points;
    out.report.seeds += g.report.seeds;
    out.report.seconds_grid += g.report.seconds_grid;
    out.report.seconds_grow += g.report.seconds_grow;
    out.report.spacing = std::max(out.report.spacing, g.report.spacing);
    g = TileGrowth{};
  }
  SeamStitcher stitcher(source, options, n);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    out.triangles_stitched += stitcher.stitch(t, out.xyz, kept);
    if (options.progress) options.progress(tiles.size() + t + 1, 2 * tiles.size());
  }
  out.seconds_stitch = seconds_since(start);

  const auto cleanup_start = std::chrono::steady_clock::now();
  for (std::size_t t = 0; t < kept.triangles.size(); ++t) {
    if (kept.groups.find(kept.group[t]).second)
      std::swap(kept.triangles[t][1], kept.triangles[t][2]);
  }
  out.report.triangles_grown = kept.triangles.size();
  const NonManifoldReport nm = remove_non_manifold_vertices_at(kept.triangles, n, kept.second_fans);
  out.report.triangles_removed = nm.triangles_removed;
  out.report.non_manifold_vertices_fixed = nm.vertices_fixed;
  if (options.mesh.orient) {
    const TileBox bounds = [&] {
      TileBox b = tiles.empty() ? TileBox{} : tiles[0].box;
      for (const TileInfo& t : tiles) {
        for (int a = 0; a < 3; ++a) {
          b.lo[a] = std::min(b.lo[a], t.box.lo[a]);
          b.hi[a] = std::max(b.hi[a], t.box.hi[a]);
        }
      }
      return b;
    }();
    std::vector<Vec3f> positions(n);
    for (std::size_t i = 0; i < n; ++i) {
      positions[i] = {static_cast<float>(out.xyz[3 * i] - 0.5 * (bounds.lo[0] + bounds.hi[0])),
                      static_cast<float>(out.xyz[3 * i + 1] - 0.5 * (bounds.lo[1] + bounds.hi[1])),
                      static_cast<float>(out.xyz[3 * i + 2] - 0.5 * (bounds.lo[2] + bounds.hi[2]))};
    }
    out.report.components_flipped = orient_components(kept.triangles, positions);
  }
  out.triangles = std::move(kept.triangles);
  out.report.seconds_cleanup = seconds_since(cleanup_start);
  return out;
}

}  // namespace g2s
