// Stage 2 of the tiled pipeline: the seam stitcher (docs/pipeline.md, "Stage 3: the seam
// stitcher"). Tiles keep only the triangles with every corner inside them, so a strip of triangles
// across each seam is missing. Tiles are visited in index order; at tile i the seams with its
// already visited neighbours are closed by growing G2S over the points within the band width of
// those seams, with every live triangle that touches those points loaded into the Point-Edge Map:
// their open edges are the front, and no new triangle can give an edge a third triangle or a vertex
// a crossing fan the clean-up cannot see. Points farther out are loaded as context, so the Gabriel
// test sees the whole neighbourhood; they grow nothing, but the live triangles at those of this
// tile and the earlier ones are loaded too (their stars are then whole), so that holes reaching
// past the band are filled over them. A new triangle that crosses a live triangle touching only
// the rest of the context (not loaded, so the grower could not see it) is left out.
//
// Memory: only the live mesh is kept (stitch/live_mesh.hpp). After each tile the points no later
// seam can reach are finished and the triangles around them released to the sink
// (cleanup/release.cpp), so what stays is the band along the seams still open.
//
// Orientation: every triangle belongs to an orientation group (from its tile or seam); the
// stitcher joins the groups meeting at a seam with the parity their normals vote for (where the
// vote is clear; others as it connects them), and the end flips each group so that all of a
// component faces one way, and the component outward as the in-memory mesher does.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <tuple>

#include "common/id_map.hpp"
#include "common/local_frame.hpp"
#include "common/seconds_since.hpp"
#include "common/triangle_intersection.hpp"
#include "g2s/error.hpp"
#include "g2s/tile_stages.hpp"
#include "grid/hash_grid.hpp"
#include "grow/crossings.hpp"
#include "grow/grower.hpp"
#include "stitch/live_mesh.hpp"
#include "stitch/release.hpp"
#include "stitch/seam_reach.hpp"

namespace g2s {
namespace {

class SeamStitcher {
 public:
  SeamStitcher(const TileSource& source, const PipelineOptions& options)
      : source_(source), options_(options) {}

  // Closes the seams between `tile` and its neighbours with smaller indices, adding the new
  // triangles to `live`. Returns how many were added and how many were left out because a
  // corner was already finished.
  std::pair<std::uint64_t, std::uint64_t> stitch(std::size_t tile, const SeamReach& reach,
                                                 LiveMesh& live) {
    const std::span<const TileInfo> tiles = source_.tiles();
    const TileBox& box = tiles[tile].box;
    const double band = reach.band;
    const std::vector<std::size_t> near = tiles_near(tiles, tile, reach.context);
    std::vector<std::size_t> earlier;
    for (std::size_t j : near) {
      if (j < tile) earlier.push_back(j);
    }
    if (earlier.empty()) return {0, 0};

    // The band (growable) and its context, from the tile and its neighbours' borders.
    ids_.clear();
    local_.clear();
    growable_.clear();
    fillable_.clear();
    local_of_.clear();
    // Positions are taken in double and put in a float frame once all are known (below).
    seam_xyz_.clear();
    // Returns the point's place in ids_. `seam` is the point's distance from the seam, or more
    // than the context for a point of a later tile.
    auto take = [&](Index id, double seam, const double* p) {
      const auto next = static_cast<std::uint32_t>(ids_.size());
      const std::uint32_t at = local_of_.insert(id, next);
      if (at != next) return at;
      // A point of the context that is live and not finished has its whole star loaded (every
      // live triangle at it, below), so holes may be filled over it; a band point is such a
      // point (within the tile's reach) and may also grow. A finished one, or one of a later
      // tile, is context only.
      const std::uint32_t s = live.slot(id);
      const bool whole = seam <= reach.context && s != IdMap::kMissing &&
                         (live.flags[s] & LiveMesh::kFinished) == 0;
      if (s != IdMap::kMissing) {
        live.flags[s] |= whole ? LiveMesh::kStarLoaded : LiveMesh::kInContext;
      }
      ids_.push_back(id);
      growable_.push_back(whole && seam <= band);
      fillable_.push_back(whole);
      seam_xyz_.insert(seam_xyz_.end(), p, p + 3);
      return at;
    };
    const double later = reach.context + 1;  // a later tile's points are context only
    {
      const TilePoints own = source_.load_border(tile, reach.context);
      for (std::size_t k = 0; k < own.size(); ++k) {
        double d = later;
        for (std::size_t j : earlier) d = std::min(d, box_distance(tiles[j].box, &own.xyz[3 * k]));
        if (d <= reach.context) take(own.ids[k], d, &own.xyz[3 * k]);
      }
    }
    for (std::size_t j : near) {
      const TilePoints border = source_.load_border(j, reach.context);
      for (std::size_t k = 0; k < border.size(); ++k) {
        const double d = box_distance(box, &border.xyz[3 * k]);
        if (d <= reach.context) take(border.ids[k], j < tile ? d : later, &border.xyz[3 * k]);
      }
    }
    // Every live triangle touching a point whose star is loaded, presented facing as its group
    // currently does, so the grower starts from what earlier seams already decided; in the order
    // they were made. Those touching only the rest of the context are kept aside for the crossing
    // check (crossing_context).
    preload_.clear();
    preload_group_.clear();
    preload_live_.clear();
    context_slots_.clear();
    for (std::size_t t = 0; t < live.triangles.size(); ++t) {
      const Triangle& tri = live.triangles[t];
      const std::uint8_t touches = live.flags[tri[0]] | live.flags[tri[1]] | live.flags[tri[2]];
      if (!(touches & LiveMesh::kStarLoaded)) {
        if (touches & LiveMesh::kInContext) {
          context_slots_.insert(context_slots_.end(), tri.begin(), tri.end());
        }
        continue;
      }
      const auto [root, parity] = live.groups.find(live.group[t]);
      Triangle corners{};  // places in ids_ for now
      for (int k = 0; k < 3; ++k) {
        const Index s = tri[k];
        corners[k] = take(live.id[s], later, &live.xyz[3 * std::size_t{s}]);
      }
      if (parity) std::swap(corners[1], corners[2]);
      preload_.push_back(corners);
      preload_group_.push_back(root);
      preload_live_.push_back(static_cast<std::uint32_t>(t));
    }
    for (const Index id : ids_) {
      const std::uint32_t s = live.slot(id);
      if (s != IdMap::kMissing) live.flags[s] &= ~(LiveMesh::kStarLoaded | LiveMesh::kInContext);
    }
    // The tile's float frame, as in its own growth, unless the seam's points lie far from it (a
    // tile stretched by a stray point it could not be cut from): then one on their own box, so
    // that corners kept apart in their tiles' frames stay apart here.
    const LocalFrame frame = finer_frame(tile_frame(tiles[tile]), points_box(seam_xyz_, box));
    local_ = frame.convert(seam_xyz_);
    bool floats_exact = frame.exact(seam_xyz_);
    context_corners_.clear();
    context_xyz_.clear();
    for (const Index s : context_slots_) {
      const double* p = &live.xyz[3 * std::size_t{s}];
      context_corners_.push_back(frame.point(p));
      context_xyz_.push_back({p[0], p[1], p[2]});
      floats_exact = floats_exact && frame.exact(p);
    }

    // Kept corners stay in the grid in a cloud of twins: a seam's float frame may judge a pair at
    // the twin distance otherwise than the tile's did.
    std::vector<std::uint8_t> corner;
    if (source_.twin_distance() > 0) {
      corner.assign(ids_.size(), 0);
      for (const Triangle& t : preload_) {
        for (const Index v : t) corner[v] = 1;
      }
    }
    const HashGrid grid(local_, ids_, source_.group_distance(), source_.twin_distance(), corner);
    // Place in ids_ -> grid index, for the preloaded corners (the grid keeps the smallest id of
    // exact duplicates, as every tile's grid does, so all kept corners are in it, unless two of
    // them round to one float here: a seam whose points lie too far apart for float, as where
    // stray points scattered far from a scan stretch a tile no cut could free them from).
    grid_of_.assign(ids_.size(), kNoIndex);
    for (std::uint32_t k = 0; k < grid.size(); ++k) grid_of_[grid.source(k)] = k;
    for (Triangle& t : preload_) {
      for (Index& v : t) {
        v = grid_of_[v];
        if (v == kNoIndex) {
          throw Error(Exit::no_surface,
                      "no surface can be formed: the points of a seam lie too far apart for the "
                      "mesher's float coordinates, which merge two of its kept points (stray "
                      "points far from the rest?); nothing written");
        }
      }
    }
    std::vector<std::uint8_t> growable(grid.size()), fillable(grid.size());
    for (std::uint32_t k = 0; k < grid.size(); ++k) {
      growable[k] = growable_[grid.source(k)];
      fillable[k] = fillable_[grid.source(k)];
    }

    vote_orientation(grid, growable);

    MeshOptions mesh_options = options_.mesh;
    mesh_options.progress = {};
    exact_ = detail::output_positions(grid, seam_xyz_, floats_exact);
    GrowContext context{preload_, preload_group_, growable, links_, options_.stitch_retries, {}};
    context.fillable = fillable;
    context.cloud_spacing = source_.cloud_spacing();
    context.exact_positions = exact_;
    context.exact_origin = frame.origin();
    GrowResult grown = grow_mesh(grid, mesh_options, context);
    const std::vector<std::uint8_t> crossing = crossing_context(grid, grown.triangles);

    // Orientation: per grower group, the first preloaded triangle anchors it to a live group.
    const std::size_t preloaded = preload_.size();
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
      live.groups.unite(preload_group_[a], preload_group_[k],
                        static_cast<std::uint8_t>(grown.flip[k] ^ grown.flip[a]));
    }
    // Live triangles the grower took off to fill a widened hole (their groups still anchor).
    if (!grown.removed_preload.empty()) {
      std::vector<std::uint32_t> removed;
      for (std::uint32_t k : grown.removed_preload) removed.push_back(preload_live_[k]);
      live.remove_triangles(removed);
    }
    std::vector<std::uint32_t> fresh(group_ids.size(), kNoIndex);  // groups with no anchor
    std::uint64_t added = 0, dropped = 0;
    for (std::size_t k = 0; k < grown.triangles.size(); ++k) {
      Triangle t = grown.triangles[k];
      Triangle slots{};
      bool finished = false;
      for (int c = 0; c < 3; ++c) {
        slots[c] = live.slot(grid.id(t[c]));
        finished = finished || slots[c] == IdMap::kMissing ||
                   (live.flags[slots[c]] & LiveMesh::kFinished) != 0;
      }
      if (finished) {
        ++dropped;
        continue;
      }
      if (crossing[k]) {
        ++dropped;
        for (const std::uint32_t c : slots) live.flags[c] |= LiveMesh::kSuspect;  // fans may split
        continue;
      }
      const std::size_t s = slot(grown.group[preloaded + k]);
      std::uint8_t flip = grown.flip[preloaded + k];
      std::uint32_t group = 0;
      if (anchor_of[s] != kNoIndex) {
        flip ^= grown.flip[anchor_of[s]];
        group = preload_group_[anchor_of[s]];
      } else {
        if (fresh[s] == kNoIndex) fresh[s] = live.add_group();
        group = fresh[s];
      }
      if (flip) std::swap(slots[1], slots[2]);
      live.add_triangle(slots, group);
      ++added;
    }
    for (Index v : grown.second_fans) {
      const std::uint32_t s = live.slot(grid.id(v));
      if (s != IdMap::kMissing) live.flags[s] |= LiveMesh::kSuspect;
    }
    return {added, dropped};
  }

 private:
  // Per triangle the seam made: whether it crosses a live triangle that touches only context
  // points (context_corners_). The grower saw only the preloaded ones, those touching the band;
  // a new triangle near the band's edge can reach past it (its corners may be a preloaded
  // triangle's, outside the band) and cross one of these (on very noisy clouds in small tiles).
  std::vector<std::uint8_t> crossing_context(const HashGrid& grid,
                                             std::span<const Triangle> made) const {
    std::vector<std::uint8_t> crossing(made.size(), 0);
    if (made.empty() || context_corners_.empty()) return crossing;
    const detail::TriangleCells cells(grid.points(), made);
    for (std::size_t x = 0; x < context_corners_.size(); x += 3) {
      const Vec3f* live_corners = &context_corners_[x];
      const detail::Box box = detail::enclose(
          detail::enclose({live_corners[0], live_corners[0]}, live_corners[1]), live_corners[2]);
      cells.for_each_near(box.lo, box.hi, [&](std::uint32_t k, const detail::Box&) {
        if (crossing[k]) return;
        const Triangle& t = made[k];
        if (exact_.empty()) {
          const Vec3f corners[3] = {grid.point(t[0]), grid.point(t[1]), grid.point(t[2])};
          crossing[k] = triangles_cross(corners, live_corners);
        } else {
          const Vec3 corners[3] = {exact_[t[0]], exact_[t[1]], exact_[t[2]]};
          crossing[k] = triangles_cross(corners, &context_xyz_[x]);
        }
      });
    }
    return crossing;
  }

  // How the live groups meeting at this seam face each other, decided before growing by a vote
  // of the surface normals on both sides. Left to the grower, the first triangle to join two
  // groups would decide it, and on noisy or layered scans that triangle is often a fold: every
  // later triangle along the seam then contradicts it and is refused, leaving a crack. Each
  // band point votes for its group and the group of its nearest point of another group (within
  // 3 spacings) with the dot product of their normals, if that point lies along the surface
  // (within 30 degrees of the point's tangent plane): one across it may be the other sheet of a
  // thin part, which faces the other way. The strongest pairs are joined first; a pair whose
  // sum is within twice the spread of as many random votes is left to the grower.
  void vote_orientation(const HashGrid& grid, std::span<const std::uint8_t> growable) {
    const std::uint32_t n = grid.size();
    label_.assign(n, kNoIndex);
    normal_.assign(n, Vec3{0, 0, 0});
    for (std::size_t k = 0; k < preload_.size(); ++k) {
      const Triangle& t = preload_[k];
      const Vec3 a = grid.position(t[0]);
      const Vec3 area = cross(grid.position(t[1]) - a, grid.position(t[2]) - a);
      for (Index v : t) {
        if (label_[v] == kNoIndex) label_[v] = preload_group_[k];
        if (label_[v] == preload_group_[k]) normal_[v] = normal_[v] + area;
      }
    }
    votes_.clear();
    const double radius = 3 * grid.spacing();
    for (std::uint32_t v = 0; v < n; ++v) {
      if (!growable[v] || label_[v] == kNoIndex || norm2(normal_[v]) == 0) continue;
      std::uint32_t other = kNoIndex;
      double nearest = radius * radius;
      const Vec3 pv = grid.position(v), nv = normalized(normal_[v]);
      grid.for_each_in_ball(pv, radius, [&](std::uint32_t w, double d2) {
        if (label_[w] == kNoIndex || label_[w] == label_[v] || norm2(normal_[w]) == 0) return;
        if (d2 < nearest || (d2 == nearest && w < other)) {
          nearest = d2;
          other = w;
        }
      });
      if (other == kNoIndex) continue;
      const double across = dot(grid.position(other) - pv, nv);
      if (4 * across * across > nearest) continue;
      votes_.push_back({std::min(label_[v], label_[other]), std::max(label_[v], label_[other]),
                        dot(nv, normalized(normal_[other])), 1});
    }
    // Sums per pair (in a fixed order: the same bytes on every run), strongest first.
    std::sort(votes_.begin(), votes_.end(), [](const Vote& x, const Vote& y) {
      return std::tie(x.a, x.b, x.sum) < std::tie(y.a, y.b, y.sum);
    });
    std::size_t pairs = 0;
    for (const Vote& x : votes_) {
      if (pairs > 0 && votes_[pairs - 1].a == x.a && votes_[pairs - 1].b == x.b) {
        votes_[pairs - 1].sum += x.sum;
        ++votes_[pairs - 1].count;
      } else {
        votes_[pairs++] = x;
      }
    }
    votes_.resize(pairs);
    std::sort(votes_.begin(), votes_.end(), [](const Vote& x, const Vote& y) {
      const double ax = std::abs(x.sum), ay = std::abs(y.sum);
      return ax != ay ? ax > ay : std::tie(x.a, x.b) < std::tie(y.a, y.b);
    });
    links_.clear();
    for (const Vote& x : votes_) {
      if (std::abs(x.sum) < 2 * std::sqrt(static_cast<double>(x.count))) continue;
      links_.push_back({x.a, x.b, static_cast<std::uint8_t>(x.sum < 0)});
    }
  }

  struct Vote {
    std::uint32_t a, b;  // labels, a < b
    double sum;          // > 0: they face the same way as preloaded
    std::uint32_t count;
  };

  const TileSource& source_;
  const PipelineOptions& options_;
  IdMap local_of_;  // global id -> index in ids_, for the points of the current seam
  std::vector<Index> ids_;
  std::vector<float> local_;
  std::vector<std::uint8_t> growable_, fillable_;
  std::vector<std::uint32_t> grid_of_;  // per point of ids_: its index in the seam grid
  std::vector<Triangle> preload_;
  std::vector<std::uint32_t> preload_group_;
  std::vector<std::uint32_t> preload_live_;  // per preloaded triangle: its place in the live mesh
  std::vector<double> seam_xyz_;             // per point of ids_: its position
  std::vector<Index> context_slots_;         // per live triangle touching only context: its corners
  std::vector<Vec3f> context_corners_;       // and their positions in the seam's frame
  std::vector<Vec3> context_xyz_;            // and in the output (the input's coordinates)
  // Per grid point of the seam, its position in the output, where the seam's floats are not
  // exactly those (GrowContext::exact_positions); else empty.
  std::vector<Vec3> exact_;
  // The orientation vote's scratch: per seam grid point, its label and normal.
  std::vector<std::uint32_t> label_;
  std::vector<Vec3> normal_;
  std::vector<Vote> votes_;
  std::vector<GrowContext::Link> links_;
};

// When the seams are done with a point: per tile, the seams' reach and the faces other tiles lie
// beyond, measured as the stitcher measures (Stitcher::prepare) and as
// predict_peak_live_points predicts.
struct SeamSteps {
  SeamSteps(std::span<const TileInfo> all, const PipelineOptions& options) : tiles(all) {
    for (std::size_t t = 0; t < all.size(); ++t) {
      reach.push_back(seam_reach(all, t, options));
      faces.push_back(tile_faces(all, t));
    }
  }

  // The later tiles whose seams can reach into `tile`'s box, increasing, and the largest reach
  // and margin among them.
  void later_near(std::size_t tile, std::vector<std::size_t>& later, double& inside) const {
    later.clear();
    inside = 0;
    for (std::size_t j = tile + 1; j < tiles.size(); ++j) {
      const double far = reach[j].touch + reach[j].margin;
      if (tiles[j].points > 0 && box_gap(tiles[tile].box, tiles[j].box) <= far) {
        later.push_back(j);
        inside = std::max(inside, far);
      }
    }
  }

  // The last step whose seam can touch a point of `tile` at p: the largest later tile within
  // its reach; with `margin`, within its reach and its margin (the release step).
  // `later` and `inside`: from later_near.
  std::uint32_t last_step(std::size_t tile, const double* p, std::span<const std::size_t> later,
                          double inside, bool margin) const {
    // Every other box lies beyond an open face: a point deeper than any reach is done.
    if (faces[tile].depth(p) > inside) return static_cast<std::uint32_t>(tile);
    for (std::size_t k = later.size(); k-- > 0;) {
      const SeamReach& r = reach[later[k]];
      if (box_distance(tiles[later[k]].box, p) <= r.touch + (margin ? r.margin : 0.0)) {
        return static_cast<std::uint32_t>(later[k]);
      }
    }
    return static_cast<std::uint32_t>(tile);
  }

  // Whether the live mesh holds a point of `tile` released at step `release`: a seam may look
  // it up (a later seam reaches it, or it lies within its own tile's reach and margin of an
  // open face).
  bool listed(std::size_t tile, const double* p, std::uint32_t release) const {
    return release != tile || faces[tile].depth(p) <= reach[tile].touch + reach[tile].margin;
  }

  std::span<const TileInfo> tiles;
  std::vector<SeamReach> reach;  // per tile
  std::vector<TileFaces> faces;  // per tile
};

}  // namespace

struct Stitcher::Impl {
  Impl(const TileSource& s, const PipelineOptions& o, MeshSink& k)
      : source(s),
        options(o),
        sink(k),
        steps(s.tiles(), options),
        stitcher(s, options),
        live(s.tiles().size()) {}
  // Read by prepare() on other threads while add() runs: set once, and kept off the cache lines
  // that add() writes, so the threads do not pass those lines back and forth.
  const TileSource& source;
  const PipelineOptions options;  // a copy: callers may pass a temporary
  MeshSink& sink;
  SeamSteps steps;
  Vec3 origin{0, 0, 0};
  alignas(64) SeamStitcher stitcher;
  LiveMesh live;
  ReleaseCounts released;
  PipelineSummary out;
  std::size_t next = 0;  // the tile add() expects
};

Stitcher::Stitcher(const TileSource& source, const PipelineOptions& options, MeshSink& sink) {
  if (source.point_count() >= kNoIndex) {
    throw Error(Exit::bad_input, "cloud has more than 4,294,967,294 points");
  }
  impl_ = std::make_unique<Impl>(source, options, sink);
  const std::span<const TileInfo> tiles = source.tiles();
  impl_->out.tiles = tiles.size();
  const TileBox bounds = tiles_bounds(tiles);
  impl_->origin = {0.5 * (bounds.lo[0] + bounds.hi[0]), 0.5 * (bounds.lo[1] + bounds.hi[1]),
                   0.5 * (bounds.lo[2] + bounds.hi[2])};
}

Stitcher::~Stitcher() = default;

struct PreparedTile::Data {
  // A point the live mesh must hold: a seam can reach it, or it is a corner of a triangle that
  // is not final, or it may have a second fan. `number`: its vertex number among the final
  // triangles' corners (below), or kNoIndex.
  struct Held {
    double xyz[3];
    Index id;
    std::uint32_t finish;   // the step that finishes it
    std::uint32_t release;  // the step that releases it
    std::uint32_t number;
    bool listed;  // a seam can look it up by id
  };
  std::vector<Held> held;
  // The grown triangles: the first final_triangles (final) with their corners numbered from 0
  // in order of first use, the others by their corners' places in `held`; second_fans too.
  TileGrowth growth;
  // The final triangles' corners in that order, so that the sink reads them in sequence, and
  // (triangle, number) of the corners only final triangles use, each after its last triangle.
  std::vector<Index> vertex_ids;
  std::vector<double> vertex_xyz;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> done;
  std::vector<GroupSums> sums;               // per group of the tile, over its final triangles
  std::unique_ptr<SinkBlockWork> sink_work;  // the sink's own work on the final triangles

  SinkBlock final_block() const {
    return {vertex_ids, vertex_xyz,
            std::span<const Triangle>(growth.triangles.data(), growth.final_triangles),
            std::span<const std::uint32_t>(growth.group.data(), growth.final_triangles), done};
  }
};

PreparedTile::PreparedTile() = default;
PreparedTile::~PreparedTile() = default;
PreparedTile::PreparedTile(PreparedTile&&) noexcept = default;
PreparedTile& PreparedTile::operator=(PreparedTile&&) noexcept = default;

PreparedTile Stitcher::prepare(std::size_t tile, TileGrowth growth) const {
  const Impl& m = *impl_;
  const TilePoints points =
      growth.points.size() == growth.report.points ? std::move(growth.points) : m.source.load(tile);
  growth.points = TilePoints{};
  const std::size_t n = points.size();
  if (n != growth.report.points) {
    throw Error(Exit::bad_input, "grown tile: its point count differs from the tile store's");
  }
  for (const Triangle& t : growth.triangles) {
    for (Index v : t) {
      if (v >= n) throw Error(Exit::bad_input, "grown tile: a corner is not a point of its tile");
    }
  }
  for (Index v : growth.second_fans) {
    if (v >= n) throw Error(Exit::bad_input, "grown tile: a corner is not a point of its tile");
  }
  for (Index id : points.ids) {
    if (id >= m.source.point_count()) {
      throw Error(Exit::bad_input, "tile store: a point id is out of range");
    }
  }
  PreparedTile prepared;
  prepared.data_ = std::make_unique<PreparedTile::Data>();
  PreparedTile::Data& d = *prepared.data_;
  // Per point: its place in d.held, or kNoIndex. First the corners of the triangles that are
  // not final and the suspects (marked 0), then the points a seam can reach.
  std::vector<std::uint32_t> held_at(n, kNoIndex);
  for (std::size_t k = growth.final_triangles; k < growth.triangles.size(); ++k) {
    for (Index v : growth.triangles[k]) held_at[v] = 0;
  }
  for (Index v : growth.second_fans) held_at[v] = 0;
  std::vector<std::size_t> later;
  double inside = 0;
  m.steps.later_near(tile, later, inside);
  // Each point's release step, and whether a seam can look it up, known before the final
  // triangles go out: a point only they use is announced done to the sink right after its last
  // one (a sink counting defects in stride then holds few points open).
  for (std::size_t k = 0; k < n; ++k) {
    const double* p = &points.xyz[3 * k];
    const std::uint32_t release = m.steps.last_step(tile, p, later, inside, true);
    const bool listed = m.steps.listed(tile, p, release);
    if (!listed && held_at[k] == kNoIndex) continue;
    const std::uint32_t finish =
        release == tile ? release : m.steps.last_step(tile, p, later, inside, false);
    held_at[k] = static_cast<std::uint32_t>(d.held.size());
    d.held.push_back({{p[0], p[1], p[2]}, points.ids[k], finish, release, kNoIndex, listed});
  }
  // The final triangles numbered as emit_triangle would number them, in order.
  const std::size_t finals = growth.final_triangles;
  std::vector<std::uint32_t> last_final(n, kNoIndex);
  for (std::size_t k = 0; k < finals; ++k) {
    for (Index v : growth.triangles[k]) last_final[v] = static_cast<std::uint32_t>(k);
  }
  std::vector<std::uint32_t> number(n, kNoIndex);
  d.sums.resize(growth.groups);
  for (std::size_t k = 0; k < finals; ++k) {
    Triangle& t = growth.triangles[k];
    add_to_sums(d.sums[growth.group[k]],
                {&points.xyz[3 * std::size_t{t[0]}], &points.xyz[3 * std::size_t{t[1]}],
                 &points.xyz[3 * std::size_t{t[2]}]},
                m.origin, {points.ids[t[0]], points.ids[t[1]], points.ids[t[2]]});
    for (Index& v : t) {
      const Index point = v;
      if (number[point] == kNoIndex) {
        number[point] = static_cast<std::uint32_t>(d.vertex_ids.size());
        d.vertex_ids.push_back(points.ids[point]);
        d.vertex_xyz.insert(d.vertex_xyz.end(), &points.xyz[3 * std::size_t{point}],
                            &points.xyz[3 * std::size_t{point} + 3]);
        if (held_at[point] != kNoIndex) d.held[held_at[point]].number = number[point];
      }
      v = number[point];
      if (last_final[point] == k && held_at[point] == kNoIndex) {
        d.done.emplace_back(static_cast<std::uint32_t>(k), number[point]);
        last_final[point] = kNoIndex;
      }
    }
  }
  for (std::size_t k = finals; k < growth.triangles.size(); ++k) {
    for (Index& v : growth.triangles[k]) v = held_at[v];
  }
  for (Index& v : growth.second_fans) v = held_at[v];
  d.growth = std::move(growth);
  d.sink_work = m.sink.prepare(d.final_block());
  return prepared;
}

void Stitcher::add(std::size_t tile, PreparedTile prepared) {
  Impl& m = *impl_;
  if (tile != m.next) throw Error(Exit::failure, "stitch: tiles must come in index order");
  if (!prepared.data_) throw Error(Exit::failure, "stitch: a tile was not prepared");
  ++m.next;
  const auto start = std::chrono::steady_clock::now();
  const PreparedTile::Data& d = *prepared.data_;
  const TileGrowth& growth = d.growth;
  LiveMesh& live = m.live;
  const auto base = static_cast<std::uint32_t>(live.groups.size());
  for (std::uint32_t g = 0; g < growth.groups; ++g) {
    live.add_group();
    live.sums[base + g] = d.sums[g];
  }
  // Final triangles go to the output now, numbered on from the vertices given so far.
  const std::uint32_t first_number = m.released.vertices;
  m.sink.block(d.final_block(), first_number, base, std::move(prepared.data_->sink_work));
  m.released.vertices += static_cast<std::uint32_t>(d.vertex_ids.size());
  m.released.triangles += growth.final_triangles;
  std::vector<std::uint32_t> slot_of_held(d.held.size());
  for (std::size_t h = 0; h < d.held.size(); ++h) {
    const PreparedTile::Data::Held& p = d.held[h];
    slot_of_held[h] = live.add_point(p.id, p.xyz, p.finish, p.release, p.listed);
    live.number[slot_of_held[h]] = p.number == kNoIndex ? kNoIndex : first_number + p.number;
  }
  for (std::size_t k = growth.final_triangles; k < growth.triangles.size(); ++k) {
    const Triangle& t = growth.triangles[k];
    live.add_triangle({slot_of_held[t[0]], slot_of_held[t[1]], slot_of_held[t[2]]},
                      base + growth.group[k]);
  }
  for (Index h : growth.second_fans) live.flags[slot_of_held[h]] |= LiveMesh::kSuspect;
  MeshReport& r = m.out.report;
  r.points += growth.report.points;
  r.seeds += growth.report.seeds;
  r.duplicates_merged += growth.report.duplicates_merged;
  r.seconds_grid += growth.report.seconds_grid;
  r.seconds_grow += growth.report.seconds_grow;
  r.seconds_finish += growth.report.seconds_finish;
  r.triangles_grown += growth.triangles.size() + growth.report.triangles_removed;
  r.triangles_removed += growth.report.triangles_removed;
  r.non_manifold_vertices_fixed += growth.report.non_manifold_vertices_fixed;
  r.spacing = std::max(r.spacing, growth.report.spacing);
  prepared = PreparedTile{};
  const auto [added, dropped] = m.stitcher.stitch(tile, m.steps.reach[tile], live);
  m.out.triangles_stitched += added;
  m.out.seam_triangles_dropped += dropped;
  r.triangles_grown += added;
  const auto release_start = std::chrono::steady_clock::now();
  release_finished(live, tile, m.origin, m.sink, m.released);
  r.seconds_cleanup += seconds_since(release_start);
  m.out.seconds_stitch += seconds_since(start);
}

PipelineSummary Stitcher::finish() {
  Impl& m = *impl_;
  if (m.next != m.source.tiles().size()) throw Error(Exit::failure, "stitch: a tile is missing");
  if (!m.live.triangles.empty()) {
    throw Error(Exit::failure, "stitch: triangles left unfinished after the last tile");
  }
  PipelineSummary& out = m.out;
  out.triangles = m.released.triangles;
  out.vertices = m.released.vertices;
  out.peak_live_points = m.live.peak_points;
  out.report.triangles_removed += m.released.non_manifold.triangles_removed;
  out.report.non_manifold_vertices_fixed += m.released.non_manifold.vertices_fixed;
  out.vertices_unjudged = m.released.non_manifold.vertices_unjudged;
  const std::vector<std::uint8_t> flip =
      group_flips(m.live.groups, m.live.sums, m.options.mesh.orient, out.report.components_flipped);
  m.sink.finish(flip);
  return out;
}

std::uint64_t predict_peak_live_points(const TileSource& source, const PipelineOptions& options) {
  const std::span<const TileInfo> tiles = source.tiles();
  const SeamSteps steps(tiles, options);
  // Per thread: the change in points held at each step (+1 at a point's tile, -1 after the step
  // that releases it).
  tbb::enumerable_thread_specific<std::vector<std::int64_t>> changes(
      std::vector<std::int64_t>(tiles.size() + 1, 0));
  const auto count_tile = [&](std::size_t t, std::vector<std::size_t>& later) {
    double inside = 0;
    steps.later_near(t, later, inside);
    std::vector<std::int64_t>& change = changes.local();
    const TilePoints points = source.load(t);
    for (std::size_t k = 0; k < points.size(); ++k) {
      const double* p = &points.xyz[3 * k];
      const std::uint32_t release = steps.last_step(t, p, later, inside, true);
      if (!steps.listed(t, p, release)) continue;
      ++change[t];
      --change[release + 1];
    }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tiles.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<std::size_t> later;
                      for (std::size_t t = range.begin(); t < range.end(); ++t) {
                        if (tiles[t].points > 0) count_tile(t, later);
                      }
                    });
  std::vector<std::int64_t> change(tiles.size() + 1, 0);
  for (const std::vector<std::int64_t>& local : changes) {
    for (std::size_t step = 0; step < change.size(); ++step) change[step] += local[step];
  }
  std::int64_t held = 0, peak = 0;
  for (const std::int64_t c : change) peak = std::max(peak, held += c);
  return static_cast<std::uint64_t>(peak);
}

}  // namespace g2s
