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

// Everything kept so far, in global ids, with each triangle's orientation group. Triangles are
// kept step by step (step i: tile i's own, then its seams), each step recording the tiles its
// triangles' corners lie in, so a seam looks only at the steps that reached its tiles.
struct KeptMesh {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> group;
  ParityUnionFind groups;
  std::vector<Index> second_fans;
  std::vector<std::uint32_t> tile_of;                // by global id, for the tiles added so far
  std::vector<std::size_t> step_begin;               // per step: its first triangle
  std::vector<std::vector<std::size_t>> step_tiles;  // per step: its triangles' tiles, sorted

  void add(const Triangle& t, std::uint32_t g) {
    triangles.push_back(t);
    group.push_back(g);
  }
};

class SeamStitcher {
 public:
  SeamStitcher(const TileSource& source, const PipelineOptions& options, std::size_t ids)
      : source_(source), options_(options), in_band_(ids, 0), loaded_(ids, 0) {}

  // Closes the seams between `tile` and its neighbours with smaller indices. xyz: positions by
  // global id, filled for the tiles up to `tile`.
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
    std::vector<std::size_t>& touched = kept.step_tiles[tile];
    touched = earlier;  // tiles_near lists them in index order, all below `tile`
    touched.push_back(tile);
    if (earlier.empty()) return 0;

    // The band (growable) and its context, from the tile and its neighbours' borders.
    ids_.clear();
    local_.clear();
    // Positions in a float frame at the tile's centre (offsets computed in double).
    auto take = [&](Index id, bool growable, const double* p) {
      if (loaded_[id]) return;
      loaded_[id] = 1;
      in_band_[id] = growable;
      ids_.push_back(id);
      for (int a = 0; a < 3; ++a) {
        local_.push_back(static_cast<float>(p[a] - 0.5 * (box.lo[a] + box.hi[a])));
      }
    };
    {
      const TilePoints own = source_.load_border(tile, reach);
      for (std::size_t k = 0; k < own.size(); ++k) {
        double d = reach + 1;
        for (std::size_t j : earlier) d = std::min(d, box_distance(tiles[j].box, &own.xyz[3 * k]));
        if (d <= reach) take(own.ids[k], d <= band, &own.xyz[3 * k]);
      }
    }
    for (std::size_t j : near) {
      const TilePoints border = source_.load_border(j, reach);
      for (std::size_t k = 0; k < border.size(); ++k) {
        const double d = box_distance(box, &border.xyz[3 * k]);
        if (d <= reach) take(border.ids[k], j < tile && d <= band, &border.xyz[3 * k]);
      }
    }
    // Every kept triangle touching the band, presented facing as its group currently does, so
    // the grower starts from what earlier seams already decided. Its corners are in tiles up to
    // this one, whose positions `xyz` already holds.
    preload_.clear();
    preload_group_.clear();
    // Band points lie in this tile and its earlier neighbours: only the steps that touched one
    // of those tiles kept triangles that can touch the band. Taken in the order they were kept.
    const std::size_t end = kept.triangles.size();
    for (std::size_t step = 0; step <= tile; ++step) {
      const std::vector<std::size_t>& other = kept.step_tiles[step];
      bool shared = false;
      for (std::size_t a = 0, b = 0; a < other.size() && b < touched.size() && !shared;) {
        shared = other[a] == touched[b];
        if (other[a] < touched[b]) {
          ++a;
        } else {
          ++b;
        }
      }
      if (!shared) continue;
      const std::size_t last = step < tile ? kept.step_begin[step + 1] : end;
      for (std::size_t t = kept.step_begin[step]; t < last; ++t) {
        const Triangle& tri = kept.triangles[t];
        if (!in_band_[tri[0]] && !in_band_[tri[1]] && !in_band_[tri[2]]) continue;
        const auto [root, parity] = kept.groups.find(kept.group[t]);
        preload_.push_back(parity ? Triangle{tri[0], tri[2], tri[1]} : tri);
        preload_group_.push_back(root);
        for (Index v : tri) take(v, in_band_[v], &xyz[3 * std::size_t{v}]);
      }
    }

    const HashGrid grid(local_, ids_);
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
      kept.add({grid.id(t[0]), grid.id(t[1]), grid.id(t[2])}, group);
      // A corner taken from a preloaded triangle can lie in a tile beyond this seam's.
      for (Index v : kept.triangles.back()) touched.push_back(kept.tile_of[v]);
    }
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
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
  std::vector<float> local_;
  std::vector<Triangle> preload_;
  std::vector<std::uint32_t> preload_group_;
};

}  // namespace

struct Stitcher::Impl {
  Impl(const TileSource& s, const PipelineOptions& o)
      : source(s), options(o), n(s.point_count()), stitcher(s, o, n) {}
  const TileSource& source;
  const PipelineOptions& options;
  const std::uint64_t n;
  SeamStitcher stitcher;
  KeptMesh kept;
  PipelineMesh out;
  std::size_t next = 0;  // the tile add() expects
};

Stitcher::Stitcher(const TileSource& source, const PipelineOptions& options) {
  if (source.point_count() > kNoIndex) {
    throw Error(Exit::bad_input, "cloud has more than 4,294,967,295 points");
  }
  impl_ = std::make_unique<Impl>(source, options);
  impl_->out.tiles = source.tiles().size();
  impl_->out.xyz.assign(3 * impl_->n, 0.0);
  impl_->kept.tile_of.assign(impl_->n, 0);
  impl_->kept.step_begin.assign(source.tiles().size(), 0);
  impl_->kept.step_tiles.resize(source.tiles().size());
}

Stitcher::~Stitcher() = default;

void Stitcher::add(std::size_t tile, TileGrowth growth) {
  Impl& m = *impl_;
  if (tile != m.next) throw Error(Exit::failure, "stitch: tiles must come in index order");
  ++m.next;
  const auto start = std::chrono::steady_clock::now();
  const TilePoints points =
      growth.points.size() == growth.report.points ? std::move(growth.points) : m.source.load(tile);
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (points.ids[k] >= m.n)
      throw Error(Exit::bad_input, "tile store: a point id is out of range");
    std::copy_n(&points.xyz[3 * k], 3, &m.out.xyz[3 * std::size_t{points.ids[k]}]);
    m.kept.tile_of[points.ids[k]] = static_cast<std::uint32_t>(tile);
  }
  m.kept.step_begin[tile] = m.kept.triangles.size();
  const auto base = static_cast<std::uint32_t>(m.kept.groups.size());
  for (std::uint32_t k = 0; k < growth.groups; ++k) m.kept.groups.add();
  for (std::size_t k = 0; k < growth.triangles.size(); ++k) {
    m.kept.add(growth.triangles[k], base + growth.group[k]);
  }
  m.kept.second_fans.insert(m.kept.second_fans.end(), growth.second_fans.begin(),
                            growth.second_fans.end());
  MeshReport& r = m.out.report;
  r.points += growth.report.points;
  r.seeds += growth.report.seeds;
  r.duplicates_merged += growth.report.duplicates_merged;
  r.seconds_grid += growth.report.seconds_grid;
  r.seconds_grow += growth.report.seconds_grow;
  r.spacing = std::max(r.spacing, growth.report.spacing);
  growth = TileGrowth{};
  m.out.triangles_stitched += m.stitcher.stitch(tile, m.out.xyz, m.kept);
  m.out.seconds_stitch += seconds_since(start);
}

PipelineMesh Stitcher::finish() {
  Impl& m = *impl_;
  if (m.next != m.source.tiles().size()) throw Error(Exit::failure, "stitch: a tile is missing");
  const std::span<const TileInfo> tiles = m.source.tiles();
  PipelineMesh& out = m.out;
  KeptMesh& kept = m.kept;
  const auto cleanup_start = std::chrono::steady_clock::now();
  for (std::size_t t = 0; t < kept.triangles.size(); ++t) {
    if (kept.groups.find(kept.group[t]).second) {
      std::swap(kept.triangles[t][1], kept.triangles[t][2]);
    }
  }
  out.report.triangles_grown = kept.triangles.size();
  const NonManifoldReport nm =
      remove_non_manifold_vertices_at(kept.triangles, m.n, kept.second_fans);
  out.report.triangles_removed = nm.triangles_removed;
  out.report.non_manifold_vertices_fixed = nm.vertices_fixed;
  if (m.options.mesh.orient) {
    const TileBox bounds = tiles_bounds(tiles);
    std::vector<Vec3f> positions(m.n);
    for (std::size_t i = 0; i < m.n; ++i) {
      positions[i] = {static_cast<float>(out.xyz[3 * i] - 0.5 * (bounds.lo[0] + bounds.hi[0])),
                      static_cast<float>(out.xyz[3 * i + 1] - 0.5 * (bounds.lo[1] + bounds.hi[1])),
                      static_cast<float>(out.xyz[3 * i + 2] - 0.5 * (bounds.lo[2] + bounds.hi[2]))};
    }
    out.report.components_flipped = orient_components(kept.triangles, positions);
  }
  out.triangles = std::move(kept.triangles);
  out.report.seconds_cleanup = seconds_since(cleanup_start);
  return std::move(out);
}

PipelineMesh stitch_tiles(const TileSource& source, std::vector<TileGrowth> growths,
                          const PipelineOptions& options) {
  if (growths.size() != source.tiles().size()) {
    throw Error(Exit::failure, "stitch: one growth per tile");
  }
  Stitcher stitcher(source, options);
  for (std::size_t t = 0; t < growths.size(); ++t) {
    stitcher.add(t, std::move(growths[t]));
    if (options.progress) options.progress(t + 1, growths.size());
  }
  return stitcher.finish();
}

}  // namespace g2s
