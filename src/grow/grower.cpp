// G2S mesh growing, after Di Angelo & Giaccari (2011), "A fast algorithm for manifold
// reconstruction of surfaces" §3-4, and docs/algorithm.md §2-4. For each free front edge, the
// Gabriel walk picks the point whose smallest circumscribing ball with the edge holds no other
// candidate; the discrete priority queue (radius level, then flatness level) meshes the flattest,
// best-sampled regions first; the Point-Edge Map keeps every edge manifold and every pair of
// neighbouring triangles consistently oriented, and the crossing guard refuses a triangle that
// would cross one made before.
#include "grow/grower.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>

#include "cleanup/cleanup.hpp"
#include "common/edge_map.hpp"
#include "common/seconds_since.hpp"
#include "common/separating_planes.hpp"
#include "common/union_find.hpp"
#include "grow/bucket_queue.hpp"
#include "grow/crossings.hpp"
#include "grow/gabriel_walk.hpp"
#include "grow/hole_filling.hpp"

namespace g2s {
namespace {

// A free edge a->b, as traversed by its only triangle; cand caches the point chosen for it when
// it was re-queued at a worse priority (re-validated when popped).
struct FrontEdge {
  Index a, b;
  std::uint32_t triangle;
  Index cand;
};

struct PoolPoint {
  WalkPoint walk;  // dist2: squared distance to the edge midpoint
  double ahead;    // distance along the growing direction
};

struct Candidate {
  Index point = kNoIndex;
  int priority = 0;
};

bool traverses(const Triangle& t, Index u, Index v) {
  return (t[0] == u && t[1] == v) || (t[1] == u && t[2] == v) || (t[2] == u && t[0] == v);
}

std::uint64_t edge_key(Index u, Index v) {
  return std::uint64_t{std::min(u, v)} << 32 | std::max(u, v);
}

Index apex(const Triangle& t, Index u, Index v) {
  for (Index w : t) {
    if (w != u && w != v) return w;
  }
  return kNoIndex;
}

class Grower {
 public:
  Grower(const HashGrid& grid, const MeshOptions& options, const GrowContext& context)
      : grid_(grid),
        options_(options),
        growable_(context.growable),
        fillable_(context.fillable),
        retries_(context.retries),
        levels_(static_cast<int>(options.radius_steps.size())),
        flat_levels_(std::max(1, options.flatness_levels)),
        edges_(grid.size()),
        seed_tried_(grid.size(), 0),
        positions_(grid, context.exact_positions, context.exact_origin),
        guard_(std::in_place, grid, positions_),
        state_(grid.size(), 0),
        queue_(std::max(1, levels_ * flat_levels_)),
        last_priority_(std::max(1, levels_ * flat_levels_) - 1),
        max_fold_(options.max_fold_deg * std::numbers::pi / 180.0),
        cos_max_fold_(std::cos(max_fold_)),
        radius_floor_(0.5 * grid.spacing()),
        radius_cap_(options.max_radius *
                    (context.cloud_spacing > 0
                         ? std::max(grid.spacing_lower_bound(), context.cloud_spacing)
                         : grid.spacing())) {
    // Noisy scans grow up to about three triangles a point before the clean-up; reserving more
    // costs only address space (pages are touched as triangles come) and saves copying.
    const std::size_t expected = std::size_t{4} * grid.size();
    triangles_.reserve(expected);
    group_.reserve(expected);
    flip_.reserve(expected);
    // (Outside (0, pi], cos does not order the angles as needed: acos decides.)
    for (int k = 1; k <= flat_levels_ && max_fold_ > 0 && max_fold_ <= std::numbers::pi; ++k) {
      bound_cos_.push_back(std::cos(k * max_fold_ / flat_levels_));
    }
  }

  GrowResult run(const GrowContext& context) {
    GrowResult result;
    load(context.preload, context.preload_group, context.preload_links);
    drain();
    for (std::uint32_t i = 0; i < grid_.size(); ++i) {
      if (used(i) || seed_tried_[i] || !growable(i)) continue;
      seed_tried_[i] = 1;
      if (!try_seed(i)) continue;
      ++result.seeds;
      drain();
    }
    if (options_.close_gaps) close_three_edge_gaps();
    result.seconds_finish = finish_surface();
    // Groups in the layout of the context: every preloaded triangle (those a filling replaced
    // too), then the new ones.
    const std::size_t loaded = context.preload.size(), added = triangles_.size() - preloaded_;
    result.group.resize(loaded + added);
    result.flip.resize(loaded + added);
    const auto record = [&](std::size_t at, std::uint32_t group, std::uint8_t flip) {
      const auto [root, parity] = groups_.find(group);
      result.group[at] = root;
      result.flip[at] = parity ^ flip;
    };
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      record(t < preloaded_ ? preload_index_[t] : loaded + (t - preloaded_), group_[t], flip_[t]);
    }
    for (const RemovedPreload& r : removed_preload_) {
      record(r.index, r.group, r.flip);
      result.removed_preload.push_back(r.index);
    }
    std::sort(result.removed_preload.begin(), result.removed_preload.end());
    triangles_.erase(triangles_.begin(), triangles_.begin() + static_cast<long>(preloaded_));
    result.triangles = std::move(triangles_);
    result.second_fans = std::move(second_fans_);
    return result;
  }

 private:
  bool used(Index i) const { return state_[i] & kUsed; }
  bool interior(Index i) const { return state_[i] == kUsed; }
  bool growable(Index i) const { return growable_.empty() || growable_[i]; }
  bool fillable(Index i) const { return fillable_.empty() ? growable(i) : fillable_[i] != 0; }

  // Enters the triangles kept before this run, each its own orientation group (joined where they
  // share an edge, and as `links` say); their open edges at growable points become the front.
  void load(std::span<const Triangle> preload, std::span<const std::uint32_t> labels,
            std::span<const GrowContext::Link> links) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> label_group;  // sorted by label
    for (std::size_t k = 0; k < preload.size(); ++k) {
      std::uint32_t group = 0;
      if (labels.empty()) {
        group = groups_.add();
      } else {
        const auto at =
            std::lower_bound(label_group.begin(), label_group.end(), std::pair{labels[k], 0u});
        if (at != label_group.end() && at->first == labels[k]) {
          group = at->second;
        } else {
          group = groups_.add();
          label_group.insert(at, {labels[k], group});
        }
      }
      const Triangle& t = preload[k];
      add_triangle(t[0], t[1], t[2], group, 0, false);
    }
    preloaded_ = preload.size();
    preload_index_.resize(preloaded_);
    std::iota(preload_index_.begin(), preload_index_.end(), 0u);
    auto group_of = [&](std::uint32_t label) {
      const auto at =
          std::lower_bound(label_group.begin(), label_group.end(), std::pair{label, 0u});
      return at != label_group.end() && at->first == label ? at->second : kNoIndex;
    };
    for (const GrowContext::Link& link : links) {
      const std::uint32_t a = group_of(link.a), b = group_of(link.b);
      if (a != kNoIndex && b != kNoIndex) groups_.unite(a, b, link.parity);
    }
    for (std::uint32_t t = 0; t < preloaded_; ++t) {
      for (int k = 0; k < 3; ++k) {
        const Index u = triangles_[t][k], v = triangles_[t][(k + 1) % 3];
        const std::uint32_t on = edges_.find(u, v);
        if (on == t && (growable(u) || growable(v))) queue_.push(0, {u, v, t, kNoIndex});
      }
    }
  }

  // Whether a new triangle (b, a, p) grown from front triangle `from` can share its edges with
  // triangles ap and pb (EdgeMap::kMissing: none) without contradicting how the orientation
  // groups already face; if so the groups are joined. Raw corners shared in the same direction
  // are fine across groups that can still be flipped relative to each other.
  bool join_groups(std::uint32_t from, Index a, Index p, Index b, std::uint32_t ap,
                   std::uint32_t pb) {
    struct Link {
      std::uint32_t root;
      std::uint8_t parity;  // the parity the link requires between the new triangle's root and root
    };
    const auto [root, parity] = groups_.find(group_[from]);
    const std::uint8_t own = parity ^ flip_[from];
    Link links[2];
    int count = 0;
    const std::pair<std::uint32_t, bool> shared[2] = {
        {ap, ap != EdgeMap::kMissing && traverses(triangles_[ap], p, a)},
        {pb, pb != EdgeMap::kMissing && traverses(triangles_[pb], b, p)}};
    for (const auto& [t, opposite] : shared) {
      if (t == EdgeMap::kMissing) continue;
      const auto [r, pr] = groups_.find(group_[t]);
      const std::uint8_t need = static_cast<std::uint8_t>(own ^ pr ^ flip_[t] ^ !opposite);
      if (r == root) {
        if (need != 0) return false;
      } else {
        for (int k = 0; k < count; ++k) {
          if (links[k].root == r && links[k].parity != need) return false;
        }
        links[count++] = {r, need};
      }
    }
    for (int k = 0; k < count; ++k) groups_.unite(root, links[k].root, links[k].parity);
    return true;
  }

  Vec3 normal_of(std::uint32_t t) const {
    const Triangle& tri = triangles_[t];
    const Vec3 a = grid_.position(tri[0]);
    return normalized(cross(grid_.position(tri[1]) - a, grid_.position(tri[2]) - a));
  }

  // Appends triangle (a, b, c) in orientation group `group` and updates the Point-Edge Map, the
  // open-edge counts, the crossing guard (growth only: add_triangle is not called after it) and
  // (when `grow`) the front.
  void add_triangle(Index a, Index b, Index c, std::uint32_t group, std::uint8_t flip,
                    bool grow = true) {
    const auto t = static_cast<std::uint32_t>(triangles_.size());
    triangles_.push_back({a, b, c});
    pieces_stale_ = true;
    guard_->file(t, triangles_);
    group_.push_back(group);
    flip_.push_back(flip);
    const Index corners[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      const Index u = corners[k], v = corners[(k + 1) % 3];
      const std::uint32_t other = edges_.find(u, v);
      edges_.add(u, v, t);
      if (other != EdgeMap::kMissing) {
        --state_[u];
        --state_[v];
        if (!grow) {  // preloaded neighbours: record how their groups face
          groups_.unite(
              group, group_[other & ~EdgeMap::kClosed],
              static_cast<std::uint8_t>(!traverses(triangles_[other & ~EdgeMap::kClosed], v, u)));
        }
      } else {
        ++state_[u];
        ++state_[v];
        if (grow) queue_.push(0, {u, v, t, kNoIndex});
      }
    }
    for (Index v : corners) {
      used_count_ += !used(v);
      state_[v] |= kUsed;
    }
    if (options_.progress && (t & 0xFFFF) == 0) options_.progress(used_count_, grid_.size());
  }

  // Once no front is left: closes each gap of three open edges a-b, b-x, x-a with a triangle
  // where the Point-Edge Map allows it and it folds from none of its three neighbours. The front
  // left such a gap because each edge's Gabriel point was some other point that could not join;
  // with growth over, closing it can no longer block a better triangle. Every edge still open
  // left the queue stalled (stall()).
  void close_three_edge_gaps() {
    // The stalled edges no neighbour has closed since: the open edges.
    std::size_t open = 0;
    for (std::size_t k = 0; k < stalled_.size(); ++k) {
      if (k + 8 < stalled_.size()) edges_.prefetch(stalled_[k + 8].a, stalled_[k + 8].b);
      if (edges_.find(stalled_[k].a, stalled_[k].b) == stalled_[k].triangle) {
        stalled_[open++] = stalled_[k];
      }
    }
    stalled_.resize(open);
    // Per point, the other ends of its open edges: offsets, then the ends.
    std::vector<std::uint32_t> begin(std::size_t{grid_.size()} + 1, 0);
    for (const FrontEdge& e : stalled_) ++begin[e.a + 1], ++begin[e.b + 1];
    for (std::uint32_t i = 0; i < grid_.size(); ++i) begin[i + 1] += begin[i];
    std::vector<Index> other(begin.back());
    std::vector<std::uint32_t> next(begin.begin(), begin.end() - 1);
    for (const FrontEdge& e : stalled_) {
      other[next[e.a]++] = e.b;
      other[next[e.b]++] = e.a;
    }
    const auto open_at = [&](Index u) {
      return std::span<const Index>(other).subspan(begin[u], begin[u + 1] - begin[u]);
    };
    for (const FrontEdge& e : stalled_) {
      if (!growable(e.a) || !growable(e.b)) continue;
      const Index c = apex(triangles_[e.triangle], e.a, e.b);
      const std::span<const Index> at_b = open_at(e.b);
      for (const Index x : open_at(e.a)) {
        // Each gap once, from the edge between its two smallest points: the checks do not
        // depend on the edge.
        if (x <= std::max(e.a, e.b) || x == c) continue;
        if (std::find(at_b.begin(), at_b.end(), x) == at_b.end()) continue;
        if (edges_.find(e.a, e.b) != e.triangle) break;  // closed by a gap closed before
        const Vec3 a = grid_.position(e.a), b = grid_.position(e.b);
        const Vec3 n_new = normalized(cross(a - b, grid_.position(x) - b));
        if (flatness(std::clamp(dot(normal_of(e.triangle), n_new), -1.0, 1.0)) < 0) continue;
        if (try_add(e, x)) break;
      }
    }
    stalled_ = {};
  }

  // Once growth is over (which made no crossing triangle): small holes filled, and the points
  // with more than one fan left to a single one, with the holes that leaves filled in turn
  // (docs/algorithm.md, "Hole filling"). Filling first lets a hole
  // between two fans of a point join them, where deleting one fan would leave a larger hole;
  // such a gap is not widened in that first round (most widenings of one fail, at a tenth of the
  // run on alpe): the non-manifold pass keeps one fan, and the second round widens what that
  // leaves. Then scraps of surface near the rest go (remove_scraps), and last a piece whose only
  // border is a short loop is closed with a point left over, where that makes a closed surface
  // (cap_single_loops). Returns the wall seconds it took (0 when holes are not filled).
  double finish_surface() {
    guard_.reset();  // growth is over
    if (options_.max_hole_edges < 3) return 0;
    const auto start = std::chrono::steady_clock::now();
    fill_small_holes(/*widen_fan_gaps=*/false);
    // Points whose whole star is in this run: growable, and no corner of a triangle kept from
    // before (the clean-up of the tiled pipeline judges those).
    std::vector<std::uint8_t> judged(grid_.size(), 0);
    for (std::uint32_t v = 0; v < grid_.size(); ++v) judged[v] = growable(v);
    for (std::size_t t = 0; t < preloaded_; ++t) {
      for (Index v : triangles_[t]) judged[v] = 0;
    }
    std::vector<std::uint8_t> dead;
    std::vector<Index> unjudged;
    mark_non_manifold_fans(triangles_, grid_.size(), second_fans_, judged, dead, unjudged);
    second_fans_.insert(second_fans_.end(), unjudged.begin(), unjudged.end());
    if (std::find(dead.begin(), dead.end(), 1) != dead.end()) {
      for (std::size_t t = 0; t < triangles_.size(); ++t) {
        if (!dead[t]) continue;
        for (Index v : triangles_[t]) second_fans_.push_back(v);
      }
      compact(std::move(dead));
      fill_small_holes(/*widen_fan_gaps=*/true);
    }
    if (options_.max_hole_rings > 0) remove_scraps();
    cap_single_loops();
    return seconds_since(start);
  }

  // Removes the pieces of surface that have no interior point (a lone triangle, a strip: every
  // corner on an open edge, so not a surface patch of their own) and lie within
  // kMaxLeftOutDistance spacings of a piece that stays for its own sake at every corner: on a
  // noisy scan they are triangles grown in the layer beside the sheet, each a separate hole.
  // Only pieces whose every point this run judges (fillable) go, whether grown here or loaded
  // (a seam sees every triangle at its band's points, so such a piece is whole there: a tile
  // keeps a piece that reaches into its halo, and the seam judges what is left of it once the
  // halo's triangles are dropped); their points are left out, as widened holes leave out points
  // near the surface. Scraps near only other scraps are not near a surface (the corners of a
  // cube give two opposite faces, each a scrap): they stay.
  void remove_scraps() {
    const auto n = static_cast<std::uint32_t>(grid_.size());
    const std::vector<std::uint32_t>& piece = pieces();
    // A piece may go unless it has an interior point (one on no open edge) or a point this run
    // does not judge.
    std::vector<std::uint8_t> on_open(n, 0), keep(n, 0);
    edges_.for_each_open([&](Index u, Index v) { on_open[u] = on_open[v] = 1; });
    for (std::uint32_t v = 0; v < n; ++v) {
      if (piece[v] != kNoIndex && (!on_open[v] || !fillable(v))) keep[piece[v]] = 1;
    }
    const double radius = kMaxLeftOutDistance * grid_.spacing();
    const std::vector<std::uint8_t> patch = keep;  // the pieces that stay for their own sake
    for (std::uint32_t v = 0; v < n; ++v) {
      if (piece[v] == kNoIndex || keep[piece[v]]) continue;  // a piece already known to stay
      bool near = false;
      grid_.for_each_in_ball(grid_.position(v), radius, [&](std::uint32_t w, double) {
        near = near || (piece[w] != kNoIndex && patch[piece[w]]);
      });
      if (!near) keep[piece[v]] = 1;
    }
    std::vector<std::uint8_t> dead(triangles_.size(), 0);
    bool any = false;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      if (keep[piece[triangles_[t][0]]]) continue;
      any = true;
      dead[t] = 1;
      if (t >= preloaded_) continue;
      // A loaded triangle goes as a widened ring's does: off the map here, listed in the result.
      const Triangle& tri = triangles_[t];
      for (int k = 0; k < 3; ++k) edges_.remove(tri[k], tri[(k + 1) % 3]);
      dead[t] = kUnlinked;
    }
    if (any) compact(std::move(dead));
  }

  // Closes each piece of surface whose only border is one loop of at most max_hole_edges edges
  // with a fan from the loop to a point no triangle uses: a small closed object on its own that
  // the front could not finish, such as the four points of a tetrahedron, whose fourth point
  // lies behind the seed triangle, where no search ball looks (growth looking behind the front
  // would fold fronts between the layers of a noisy scan). Hole filling leaves such a loop open:
  // it is the piece's outer border, and closing it over its own points would turn a patch into
  // a shell. A fan that closes the piece can block no later triangle. It chooses a point, as
  // growth does, so growth's tests apply (fan_fits: no unused point inside a fan triangle's
  // smallest ball, no fold beyond max_fold unless the point is the run's last), and hole
  // filling's (fill_fits: no crossing, no repeat, no context point in the ball); it faces as
  // the piece does. The piece and the point must stand
  // apart from every other piece: on a noisy scan, a lone triangle in the layer beside the sheet
  // and a noise point behind it pass the other tests.
  void cap_single_loops() {
    const auto n = static_cast<std::uint32_t>(grid_.size());
    const auto max_edges =
        static_cast<std::uint32_t>(std::min(options_.max_hole_edges, MeshOptions::kMaxHoleEdges));
    std::vector<std::uint32_t> piece = pieces();
    // Per piece: its open edges, or kNoIndex where it cannot be capped: a point with other than
    // two open edges (two loops, or one through a point twice), a point the run does not judge,
    // or a triangle loaded before the run.
    std::vector<std::uint32_t> open_edges(n, 0), ends(n, 0);
    edges_.for_each_open([&](Index u, Index v) {
      ++open_edges[piece[u]];
      ++ends[u];
      ++ends[v];
    });
    const auto exclude = [&](Index v) { open_edges[piece[v]] = kNoIndex; };
    for (std::uint32_t v = 0; v < n; ++v) {
      if (piece[v] != kNoIndex && (!fillable(v) || (ends[v] != 0 && ends[v] != 2))) exclude(v);
    }
    for (std::size_t t = 0; t < preloaded_; ++t) exclude(triangles_[t][0]);
    // A cloud meshed whole as one piece with one point left over: the fan to that point is the
    // only way to close it.
    std::uint32_t unused = 0;
    const bool only_point = one_piece(piece, unused) && unused == 1;
    const auto cappable = [&](std::uint32_t root) {
      return open_edges[root] >= 3 && open_edges[root] <= max_edges;
    };
    // The open edges of those pieces as their triangles face, by the point they leave.
    std::vector<OpenEdge> open;
    for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
      if (!cappable(piece[triangles_[t][0]])) continue;
      const Triangle tri = facing(t);
      for (int k = 0; k < 3; ++k) {
        if (triangles_on(tri[k], tri[(k + 1) % 3]) == 1)
          open.push_back({tri[k], tri[(k + 1) % 3], t});
      }
    }
    std::sort(open.begin(), open.end(),
              [](const OpenEdge& a, const OpenEdge& b) { return a.from < b.from; });
    const auto leaving = [&](Index v) {
      const auto it = std::lower_bound(open.begin(), open.end(), v,
                                       [](const OpenEdge& e, Index from) { return e.from < from; });
      return it != open.end() && it->from == v ? &*it : nullptr;
    };
    // A small object stands apart: no point of another piece within kMaxLeftOutDistance
    // spacings (nearer, a piece is the noise of that surface, as scraps are).
    const double apart = kMaxLeftOutDistance * grid_.spacing();
    const auto stands_apart = [&](Index v, std::uint32_t root) {
      bool alone = true;
      grid_.for_each_in_ball(grid_.position(v), apart, [&](std::uint32_t j, double) {
        alone = alone && (piece[j] == kNoIndex || piece[j] == root);
      });
      return alone;
    };
    std::optional<detail::TriangleCells> cells;
    std::vector<Index> loop;
    std::vector<std::uint32_t> outside;
    std::vector<std::pair<double, Index>> candidates;
    std::vector<Triangle> fan;
    for (const OpenEdge& start : open) {
      const std::uint32_t root = piece[start.from];
      if (!cappable(root)) continue;
      const std::uint32_t length = open_edges[root];
      open_edges[root] = kNoIndex;  // each piece once
      loop.clear();
      outside.clear();
      const OpenEdge* e = &start;
      do {
        loop.push_back(e->from);
        outside.push_back(e->triangle);
        e = leaving(e->to);
      } while (e != nullptr && e != &start && loop.size() < length);
      if (e != &start || loop.size() != length) continue;  // not one loop as the piece faces
      if (!std::all_of(loop.begin(), loop.end(), [&](Index v) { return stands_apart(v, root); })) {
        continue;
      }
      // The points no triangle uses near the loop, nearest its centre first.
      Vec3 centre{0, 0, 0};
      for (const Index v : loop) centre = centre + grid_.position(v);
      centre = centre * (1.0 / static_cast<double>(loop.size()));
      candidates.clear();
      grid_.for_each_in_ball(centre, radius_cap_, [&](std::uint32_t j, double d2) {
        if (piece[j] == kNoIndex && fillable(j)) candidates.push_back({d2, j});
      });
      std::sort(candidates.begin(), candidates.end());
      for (const auto& [d2, p] : candidates) {
        if (!stands_apart(p, root) || !fan_fits(loop, outside, p, piece, only_point, cells, fan)) {
          continue;
        }
        const auto [group, flip] = join_groups(outside);
        for (const Triangle& t : fan) {
          const auto id = static_cast<std::uint32_t>(triangles_.size());
          triangles_.push_back(t);
          pieces_stale_ = true;
          group_.push_back(group);
          flip_.push_back(flip);
          for (int k = 0; k < 3; ++k) edges_.add(t[k], t[(k + 1) % 3], id);
        }
        piece[p] = root;
        cells.reset();  // it holds the triangles as they were
        break;
      }
    }
  }

  // The triangles around a loop (`outside`, one per edge) face consistently along it: their
  // orientation groups become one, as they face now. Returns that group and its flip, for the
  // triangles that close the loop.
  std::pair<std::uint32_t, std::uint8_t> join_groups(std::span<const std::uint32_t> outside) {
    const std::uint32_t group = group_[outside.front()];
    for (const std::uint32_t t : outside) {
      groups_.unite(groups_.find(group).first, groups_.find(group_[t]).first, 0);
    }
    return {group, groups_.find(group).second};
  }

  // Whether one piece uses every point of the run that some triangle uses, every point is one
  // the run judges and no triangle was loaded before it (the run is one small object meshed
  // whole, or a scan's tile: only the former passes with few points left over); `unused` counts
  // the points no triangle uses. `piece` as pieces() gives it.
  bool one_piece(std::span<const std::uint32_t> piece, std::uint32_t& unused) const {
    unused = 0;
    std::uint32_t root = kNoIndex;
    for (std::uint32_t v = 0; v < piece.size(); ++v) {
      if (!fillable(v)) return false;
      if (piece[v] == kNoIndex) {
        ++unused;
      } else if (root == kNoIndex) {
        root = piece[v];
      } else if (piece[v] != root) {
        return false;
      }
    }
    return preloaded_ == 0 && root != kNoIndex;
  }

  // Lists the grown triangles whose boxes overlap `box` in loop_near_, but those `skip` says,
  // for fill_fits.
  template <class Skip>
  void gather_near(const detail::TriangleCells& cells, const detail::Box& box, Skip&& skip) {
    loop_near_.clear();
    last_blocker_ = kNoIndex;
    cells.for_each_near(box.lo, box.hi, [&](std::uint32_t other, const detail::Box& near_box) {
      if (!skip(other)) loop_near_.push(other, near_box);
    });
  }

  // Whether the fan from `loop` (its edges loop[i] -> loop[i+1] as the triangles outside them,
  // `outside`, face) to point p passes growth's tests: no point no triangle uses strictly inside
  // a fan triangle's smallest ball (the Gabriel test among the points the fan could take, with
  // the seeds' tolerance; the piece's own corners may lie inside, as the fourth corner of a
  // tetrahedron whose face is not a Gabriel triangle does) and no fold beyond max_fold from its
  // neighbours, in the fan and across the loop; and hole filling's (fill_fits). `piece` says
  // which points a triangle uses (pieces()). With `only_point` (p is the one point of the run
  // left over, the rest one piece) the fan has no choice of point, and as a hole's filling it
  // is held to no fold limit. The fan goes to `fan`.
  bool fan_fits(std::span<const Index> loop, std::span<const std::uint32_t> outside, Index p,
                std::span<const std::uint32_t> piece, bool only_point,
                std::optional<detail::TriangleCells>& cells, std::vector<Triangle>& fan) {
    const double cos_max_fold = only_point ? -1 : cos_max_fold_;
    fan.clear();
    const Vec3 c = grid_.position(p);
    Vec3 first{0, 0, 0}, previous{0, 0, 0};
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Index u = loop[i], v = loop[(i + 1) % loop.size()];
      const Vec3 a = grid_.position(u), b = grid_.position(v);
      Ball ball;
      if (!circumball(b, a, c, ball)) return false;
      const Vec3 normal = normalized(cross(a - b, c - b));
      if (dot(normal, facing_normal(outside[i])) < cos_max_fold) return false;
      if (i > 0 && dot(normal, previous) < cos_max_fold) return false;
      if (i == 0) first = normal;
      previous = normal;
      bool empty = true;
      grid_.for_each_in_ball(ball.centre, std::sqrt(ball.radius2), [&](std::uint32_t j, double d2) {
        empty = empty && (piece[j] != kNoIndex || j == p || d2 >= ball.radius2 * (1 - 1e-6));
      });
      if (!empty) return false;
      fan.push_back({v, u, p});
    }
    if (dot(first, previous) < cos_max_fold) return false;
    // The live triangles near the fan, for fill_fits.
    if (!cells) cells.emplace(grid_.points(), std::span<const Triangle>(triangles_));
    detail::Box box{grid_.point(p), grid_.point(p)};
    for (const Index v : loop) box = detail::enclose(box, grid_.point(v));
    gather_near(*cells, box, [](std::uint32_t) { return false; });
    return std::all_of(fan.begin(), fan.end(), [&](const Triangle& t) { return fill_fits(t); });
  }

  // Per point, the surface piece it is a corner of (a representative point of it: the triangles
  // sharing corners are one piece), or kNoIndex for a point no triangle uses. Worked out again
  // only after the triangles changed (pieces_stale_): the finishing asks up to five times, and on
  // a clean tile nothing changes between them.
  const std::vector<std::uint32_t>& pieces() {
    if (!pieces_stale_) return piece_of_;
    pieces_stale_ = false;
    const auto n = static_cast<std::uint32_t>(grid_.size());
    std::vector<std::uint32_t>& piece = piece_of_;
    piece.assign(n, kNoIndex);
    for (const Triangle& t : triangles_) {
      for (const Index v : t) piece[v] = v;
    }
    for (const Triangle& t : triangles_) {
      const std::uint32_t r0 = find_root(piece, t[0]);
      piece[find_root(piece, t[1])] = r0;
      piece[find_root(piece, t[2])] = r0;
    }
    for (std::uint32_t v = 0; v < n; ++v) {
      if (piece[v] != kNoIndex) piece[v] = find_root(piece, v);
    }
    return piece;
  }

  // Removes the triangles marked dead, and their edges from the Point-Edge Map (a triangle marked
  // kUnlinked is off the map already). A triangle loaded before the run goes only as part of a
  // widened hole's ring or of a scrap (kUnlinked); the result lists it. After growth the map is
  // only asked whether an edge has none, one or two triangles, so the triangle numbers it holds are
  // left as they were.
  void compact(std::vector<std::uint8_t> dead) {
    std::size_t kept = 0, kept_loaded = 0;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      const bool loaded = t < preloaded_;
      if (dead[t] && (!loaded || dead[t] == kUnlinked)) {
        const Triangle& tri = triangles_[t];
        if (dead[t] != kUnlinked) {
          for (int k = 0; k < 3; ++k) edges_.remove(tri[k], tri[(k + 1) % 3]);
        }
        if (loaded) removed_preload_.push_back({preload_index_[t], group_[t], flip_[t]});
        continue;
      }
      if (loaded) preload_index_[kept_loaded++] = preload_index_[t];
      triangles_[kept] = triangles_[t];
      group_[kept] = group_[t];
      flip_[kept] = flip_[t];
      ++kept;
    }
    preloaded_ = kept_loaded;
    preload_index_.resize(kept_loaded);
    pieces_stale_ = pieces_stale_ || kept != triangles_.size();
    triangles_.resize(kept);
    group_.resize(kept);
    flip_.resize(kept);
  }

  // One round of hole filling (fill_holes) and the removal of fillings that cross each other.
  // A widening that reaches a filling made earlier in the round gives up: the fillings are not
  // filed for the crossing test until the round ends. In the last round (widen_fan_gaps) the
  // holes that gave up so are tried once more, alone, with the round's fillings in place; in the
  // first, the last round tries them again anyway.
  void fill_small_holes(bool widen_fan_gaps) {
    std::vector<std::uint8_t> retry;  // per point: on the loop of a hole to try again
    for (int pass = 0; pass < 2; ++pass) {
      const auto grown = static_cast<std::uint32_t>(triangles_.size());
      std::vector<std::uint8_t> dead(grown, 0);
      const std::vector<std::uint8_t> only = std::move(retry);
      retry.assign(grid_.size(), 0);
      const bool met_fillings = fill_holes(dead, widen_fan_gaps, only, retry);
      dead.resize(triangles_.size(), 0);
      remove_crossing_fills(grown, dead);
      compact(std::move(dead));
      if (!widen_fan_gaps || !met_fillings) break;
    }
  }

  // The triangle as it will face once its group's orientation is applied.
  Triangle facing(std::uint32_t t) {
    Triangle tri = triangles_[t];
    if (groups_.find(group_[t]).second ^ flip_[t]) std::swap(tri[1], tri[2]);
    return tri;
  }

  // Closes every hole whose boundary loop has at most max_hole_edges edges with the
  // triangulation over the loop's points whose sharpest fold is gentlest (triangulate_loop),
  // where no edge gets a third triangle and no triangle crosses or repeats a live one or covers
  // a context point (fill_fits). The loops follow the open edges as the triangles around face;
  // at a point with several fans each edge in goes on by the first free edge out
  // counter-clockwise from it (next_open_edges), so the gap between two fans is a hole of its
  // own, and filling it makes the two fans one; a loop through a point twice is split there.
  // A hole that cannot be filled so (most often because the surface around it folds over it) is
  // widened ring by ring (widen) and filled in place of the rings, if it then can be and the
  // points that leaves out lie close to the surface (leaves_out_only_near); a loop through a
  // point with several open fans (a gap between them) only with widen_fan_gaps. A hole whose
  // rings gave up is widened once more by the ring across its edges and the triangles of its
  // corners' fans folded over it, if a survey finds only such (survey_crossings). Only holes with
  // a point set in `only` are tried, unless it is empty. Appends the filling triangles to
  // triangles_ and marks the rings kUnlinked in `dead` (sized as triangles_). Returns whether a
  // hole gave up because its widening reached a filling of this round, and sets `retry` (sized
  // as the grid) at such holes' loop points.
  bool fill_holes(std::vector<std::uint8_t>& dead, bool widen_fan_gaps,
                  std::span<const std::uint8_t> only, std::vector<std::uint8_t>& retry) {
    bool met_fillings = false;
    // The grown triangles filed for the crossing test, once a loop needs them. The fillings wait
    // in `filled` until every loop is done, so that the filed triangles stay where they are.
    std::optional<detail::TriangleCells> cells;
    std::vector<Triangle> filled;
    std::vector<OpenEdge> open;
    const auto grown = static_cast<std::uint32_t>(triangles_.size());
    // The open edges' points, from one read of the Point-Edge Map: only a triangle with two of
    // them can have an open edge, and only those are looked up.
    std::vector<std::uint8_t> on_open(grid_.size(), 0);
    edges_.for_each_open([&](Index u, Index v) { on_open[u] = on_open[v] = 1; });
    for (std::uint32_t t = 0; t < grown; ++t) {
      const Triangle& own = triangles_[t];
      if (on_open[own[0]] + on_open[own[1]] + on_open[own[2]] < 2) continue;
      const Triangle tri = facing(t);
      for (int k = 0; k < 3; ++k) {
        const Index u = tri[k], v = tri[(k + 1) % 3];
        if (!(edges_.find(u, v) & EdgeMap::kClosed)) open.push_back({u, v, t});
      }
    }
    const std::vector<std::uint32_t> next = next_open_edges(open);
    // Per point, its open fans (the open edges leaving it), counted up to two.
    std::vector<std::uint8_t> open_fans(grid_.size(), 0);
    for (const OpenEdge& e : open) open_fans[e.from] = open_fans[e.from] == 0 ? 1 : 2;
    const auto max_edges =
        static_cast<std::size_t>(std::min(options_.max_hole_edges, MeshOptions::kMaxHoleEdges));
    const int max_rings = std::clamp(options_.max_hole_rings, 0, MeshOptions::kMaxHoleRings);
    // The loops first, as runs of open edges (loop_edges[begin, begin + length)), each with its
    // component (the surface piece it borders) and whether it can be filled (every point
    // fillable, the loop closed). A loop that passes a point twice is split there into loops
    // that do not (two holes touching at a corner are two holes).
    struct Loop {
      std::uint32_t begin, length, component;
      bool closable;
    };
    const std::vector<std::uint32_t>& piece = pieces();
    std::vector<Loop> loops;
    std::vector<std::uint32_t> loop_edges, trace;
    std::vector<std::uint8_t> taken(open.size(), 0);
    std::vector<std::uint32_t> at(grid_.size(), kNoIndex);  // a point's place in `trace`
    const auto close_loop = [&](std::size_t from, bool closed) {
      Loop l{static_cast<std::uint32_t>(loop_edges.size()),
             static_cast<std::uint32_t>(trace.size() - from), piece[open[trace[from]].from],
             closed};
      for (std::size_t k = from; k < trace.size(); ++k) {
        const Index v = open[trace[k]].from;
        l.closable = l.closable && fillable(v);
        at[v] = kNoIndex;
        loop_edges.push_back(trace[k]);
      }
      trace.resize(from);
      loops.push_back(l);
    };
    for (std::uint32_t h0 = 0; h0 < open.size(); ++h0) {
      if (taken[h0]) continue;
      std::uint32_t h = h0;
      bool closed = true;
      do {
        taken[h] = 1;
        const Index v = open[h].from;
        if (at[v] != kNoIndex) close_loop(at[v], true);
        at[v] = static_cast<std::uint32_t>(trace.size());
        trace.push_back(h);
        closed = closed && next[h] != h;
        h = next[h] == h ? h0 : next[h];  // an unpaired edge ends its loop
      } while (h != h0);
      close_loop(0, closed);
    }
    // A piece's longest loop is its outer border, not a hole: filling it would close a patch
    // into a shell. Unless the cloud is a few corners of one small object: one piece uses every
    // point of the run (all of them fillable) and at most one of them is inside it, off every
    // loop (four points of a tetrahedron give two faces, or three around one corner, the rest
    // lying behind the front). A sampled patch, even a small curved one, has points inside its
    // border. Then nothing else is there for the border to continue into, and filling it closes
    // the object, where the filling neither crosses nor repeats a face (a flat quad's filling
    // would lie on it).
    std::uint32_t unused = 0;
    const bool one_object = one_piece(piece, unused) && unused == 0 &&
                            std::count(on_open.begin(), on_open.end(), std::uint8_t{0}) <= 1;
    std::vector<std::uint32_t> longest(grid_.size(), 0);
    if (!one_object) {
      for (const Loop& l : loops) longest[l.component] = std::max(longest[l.component], l.length);
    }
    // Which loops are holes, and where each open edge is, for holes that widen into others.
    HoleIndex holes{open, loop_edges, {}, {}, {}, {}, {}};
    holes.loop_of.resize(open.size());
    for (std::uint32_t i = 0; i < loops.size(); ++i) {
      const Loop& l = loops[i];
      holes.loop_begin.push_back(l.begin);
      holes.is_hole.push_back(l.closable && l.length >= 3 && l.length != longest[l.component]);
      for (std::uint32_t k = l.begin; k < l.begin + l.length; ++k) holes.loop_of[loop_edges[k]] = i;
    }
    holes.loop_begin.push_back(static_cast<std::uint32_t>(loop_edges.size()));
    holes.taken.assign(loops.size(), 0);
    holes.by_edge.reserve(open.size());
    for (std::uint32_t h = 0; h < open.size(); ++h) {
      holes.by_edge.push_back({edge_key(open[h].from, open[h].to), h});
    }
    std::sort(holes.by_edge.begin(), holes.by_edge.end());
    Attempt attempt;
    std::vector<Triangle> fill;
    detail::HoleScratch scratch;
    for (std::uint32_t i = 0; i < loops.size(); ++i) {
      const Loop& l = loops[i];
      if (!holes.is_hole[i] || holes.taken[i] || l.length > max_edges) continue;
      const std::span<const std::uint32_t> edges = holes.edges_of(i);
      if (!only.empty() && std::none_of(edges.begin(), edges.end(),
                                        [&](std::uint32_t e) { return only[open[e].from] != 0; })) {
        continue;
      }
      // A ring taken by an earlier loop's filling may have reached this loop.
      if (std::any_of(edges.begin(), edges.end(),
                      [&](std::uint32_t e) { return dead[open[e].triangle] != 0; })) {
        continue;
      }
      const auto start_attempt = [&] {
        attempt.clear();
        attempt.merged.push_back(i);
        for (const std::uint32_t e : edges) {
          attempt.add_edge(open[e].from, open[e].triangle, facing_normal(open[e].triangle));
        }
      };
      start_attempt();
      if (!cells) cells.emplace(grid_.points(), std::span<const Triangle>(triangles_));
      bool done = try_fill(*cells, attempt, scratch, fill);
      const auto through_fan_gap = [&] {
        return std::any_of(attempt.loop.begin(), attempt.loop.end(),
                           [&](Index v) { return open_fans[v] > 1; });
      };
      const bool widens = !done && (widen_fan_gaps || !through_fan_gap());
      Widening widening = Widening::widened;
      for (int round = 0; widens && !done && round < max_rings; ++round) {
        widening = widen(*cells, attempt, holes, dead, widened_edges(max_edges, round + 1));
        if (widening != Widening::widened) break;
        done =
            try_fill(*cells, attempt, scratch, fill) && leaves_out_only_near(attempt, fill, dead);
      }
      // Still open: where every triangle that crosses the first filling's candidates is of a
      // loop point's fan, and not all are across the loop's edges (a fold over the hole), they
      // are taken off with just the ring across the loop's edges, and the hole filled in their
      // place.
      if (!done && widens && max_rings > 0 && widening != Widening::met_filling) {
        start_attempt();
        try_fill(*cells, attempt, scratch, fill, /*survey=*/true);
        if (folded_over(attempt)) {
          done = widen(*cells, attempt, holes, dead, widened_edges(max_edges, 1), folded_over_) ==
                     Widening::widened &&
                 try_fill(*cells, attempt, scratch, fill) &&
                 leaves_out_only_near(attempt, fill, dead);
        }
      }
      if (!done) {
        if (widening == Widening::met_filling) {
          met_fillings = true;
          for (const std::uint32_t e : edges) retry[open[e].from] = 1;
        }
        continue;
      }
      for (const std::uint32_t m : attempt.merged) holes.taken[m] = 1;
      const auto [group, flip] = join_groups(attempt.outside);
      for (const std::uint32_t r : attempt.ring) {
        dead[r] = kUnlinked;
        const Triangle& tri = triangles_[r];
        for (int k = 0; k < 3; ++k) edges_.remove(tri[k], tri[(k + 1) % 3]);
        second_fans_.insert(second_fans_.end(), tri.begin(), tri.end());
      }
      const auto first = static_cast<std::uint32_t>(grown + filled.size());
      fill_records_.push_back({first, static_cast<std::uint32_t>(fill.size()),
                               static_cast<std::uint32_t>(fill_rings_.size()),
                               static_cast<std::uint32_t>(attempt.ring.size())});
      fill_rings_.insert(fill_rings_.end(), attempt.ring.begin(), attempt.ring.end());
      for (const Triangle& t : fill) {
        const auto id = static_cast<std::uint32_t>(grown + filled.size());
        filled.push_back(t);
        group_.push_back(group);
        flip_.push_back(flip);
        fill_loop_.push_back(static_cast<std::uint32_t>(fill_records_.size() - 1));
        for (int k = 0; k < 3; ++k) edges_.add(t[k], t[(k + 1) % 3], id);
      }
    }
    triangles_.insert(triangles_.end(), filled.begin(), filled.end());
    pieces_stale_ = pieces_stale_ || !filled.empty();
    return met_fillings;
  }

  // How many edges the border of a hole of at most max_edges edges may have once widened by
  // `rings` rings: six more per ring, as each ring of a regular triangulation (six triangles at
  // every point) has six more border edges than the one inside it. A hole is admitted by its own
  // size; its rings are bounded by how such a hole's rings grow, not by that size again.
  static std::size_t widened_edges(std::size_t max_edges, int rings) {
    return std::min(max_edges + 6 * static_cast<std::size_t>(rings),
                    static_cast<std::size_t>(MeshOptions::kMaxHoleEdges));
  }

  // An open edge u -> v as its triangle (`triangle`) faces.
  struct OpenEdge {
    Index from, to;
    std::uint32_t triangle;
  };

  // One hole's filling: its triangles (from `first`) and the ring of triangles it replaced
  // (fill_rings_[ring_begin, ring_begin + ring_size)).
  struct FillRecord {
    std::uint32_t first, count, ring_begin, ring_size;
  };

  // One round's loops of open edges: each loop's run in loop_edges, whether it is a hole that
  // may be filled (closed, every point fillable, not its piece's outer border) and whether a
  // filling took it; per open edge its loop, and the open edges by key (edge_key).
  struct HoleIndex {
    std::span<const OpenEdge> open;
    std::span<const std::uint32_t> loop_edges;
    std::vector<std::uint32_t> loop_begin;  // one more than loops: the end
    std::vector<std::uint8_t> is_hole, taken;
    std::vector<std::uint32_t> loop_of;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> by_edge;  // sorted

    std::span<const std::uint32_t> edges_of(std::uint32_t loop) const {
      return loop_edges.subspan(loop_begin[loop], loop_begin[loop + 1] - loop_begin[loop]);
    }
    // The open edge on {u, v}, or kNoIndex.
    std::uint32_t find(Index u, Index v) const {
      const std::uint64_t key = edge_key(u, v);
      const auto it = std::lower_bound(by_edge.begin(), by_edge.end(),
                                       std::pair<std::uint64_t, std::uint32_t>{key, 0});
      return it != by_edge.end() && it->first == key ? it->second : kNoIndex;
    }
  };

  // A hole to fill: its loop as the open edges around it run (loop[i] -> loop[i+1]), with the
  // triangle outside each edge and that triangle's facing normal; the ring of triangles that
  // the filling replaces (none at first), and the edges inside the hole and ring, which the
  // filling may use again once the ring is gone.
  struct Attempt {
    std::vector<Index> loop;
    std::vector<std::uint32_t> outside;
    std::vector<Vec3> around;
    std::vector<std::uint32_t> ring;         // sorted
    std::vector<std::uint64_t> inner_edges;  // sorted edge_keys
    std::vector<std::uint32_t> merged;       // the holes it fills (HoleIndex loops)

    void clear() {
      merged.clear();
      loop.clear();
      outside.clear();
      around.clear();
      ring.clear();
      inner_edges.clear();
    }
    void add_edge(Index from, std::uint32_t triangle, const Vec3& normal) {
      loop.push_back(from);
      outside.push_back(triangle);
      around.push_back(normal);
    }
    bool in_ring(std::uint32_t t) const { return std::binary_search(ring.begin(), ring.end(), t); }
  };

  // Whether every point a widened hole's filling leaves out (a corner of its ring that is not on
  // its loop) lies within kMaxLeftOutDistance spacings of the filling or of a live triangle near
  // the loop (loop_near_): a hole is closed by leaving out only points close to the surface.
  bool leaves_out_only_near(const Attempt& attempt, std::span<const Triangle> fill,
                            const std::vector<std::uint8_t>& dead) const {
    const double limit = kMaxLeftOutDistance * grid_.spacing(), limit2 = limit * limit;
    for (const std::uint32_t r : attempt.ring) {
      for (const Index v : triangles_[r]) {
        if (std::find(attempt.loop.begin(), attempt.loop.end(), v) != attempt.loop.end()) continue;
        const Vec3 p = grid_.position(v);
        double nearest2 = std::numeric_limits<double>::infinity();
        for (const Triangle& t : fill) {
          const Vec3 q = closest_on_triangle(p, grid_.position(t[0]), grid_.position(t[1]),
                                             grid_.position(t[2]));
          nearest2 = std::min(nearest2, norm2(p - q));
        }
        for (const std::uint32_t near : loop_near_.index) {
          if (nearest2 <= limit2) break;
          if (dead[near]) continue;
          const Triangle& t = triangles_[near];
          const Vec3 q = closest_on_triangle(p, grid_.position(t[0]), grid_.position(t[1]),
                                             grid_.position(t[2]));
          nearest2 = std::min(nearest2, norm2(p - q));
        }
        if (nearest2 > limit2) return false;
      }
    }
    return true;
  }

  // Triangulates the attempt's loop (triangulate_loop) into `fill`, if it can be.
  // With `survey`, the triangles asked about are held to survey_crossings instead.
  bool try_fill(const detail::TriangleCells& cells, const Attempt& attempt,
                detail::HoleScratch& scratch, std::vector<Triangle>& fill, bool survey = false) {
    if (survey) {
      folded_over_.clear();
      off_the_fans_ = false;
    }
    // The filling traverses each loop edge the other way: the loop reversed, so that edge i
    // of the reversed loop is edge n-2-i of the loop, and the closing edge stays last.
    loop_.assign(attempt.loop.rbegin(), attempt.loop.rend());
    around_.assign(attempt.around.begin(), attempt.around.end());
    std::reverse(around_.begin(), around_.end() - 1);
    fill.clear();
    const auto chord_ok = [&](std::size_t i, std::size_t j) {
      const Index u = loop_[i], v = loop_[j];
      return edges_.find(u, v) == EdgeMap::kMissing ||
             std::binary_search(attempt.inner_edges.begin(), attempt.inner_edges.end(),
                                edge_key(u, v));
    };
    // Every filling triangle lies in the loop's box: the grown triangles that may cross one
    // are those whose boxes overlap it, found once per loop. Rings taken by other fillings
    // stay among them, so that a filling taken off again can give its ring back.
    detail::Box loop_box{grid_.point(loop_[0]), grid_.point(loop_[0])};
    for (const Index v : loop_) loop_box = detail::enclose(loop_box, grid_.point(v));
    gather_near(cells, loop_box, [&](std::uint32_t other) { return attempt.in_ring(other); });
    const auto triangle_ok = [&](std::size_t i, std::size_t k, std::size_t j) {
      return survey ? !survey_crossings({loop_[i], loop_[k], loop_[j]})
                    : fill_fits({loop_[i], loop_[k], loop_[j]});
    };
    return detail::triangulate_loop(grid_.points(), loop_, around_, chord_ok, triangle_ok, scratch,
                                    fill)
        .has_value();
  }

  // Widens a hole that could not be filled by the ring of triangles around it: the triangles
  // outside its loop join the ring, holes the ring reaches join the hole, and the loop becomes
  // the border of them all. Where that border would pass a point twice, the point's whole fan
  // joins the ring too; where it would run in more than one loop (the ring closes around a pocket
  // of triangles not in it), the triangles outside every loop but the longest join the ring, so
  // that the pocket goes with it. Gives up (the attempt unusable) where the ring would take a
  // triangle at a point that is not fillable, would reach a piece's outer border or a hole
  // already filled, or where the border would have more than max_edges edges (stopped), or
  // where it would reach a filling made earlier in the round, which is not filed for the
  // crossing test until the round ends (met_filling).
  enum class Widening { widened, stopped, met_filling };
  Widening widen(const detail::TriangleCells& cells, Attempt& attempt, const HoleIndex& holes,
                 const std::vector<std::uint8_t>& dead, std::size_t max_edges,
                 std::span<const std::uint32_t> also = {}) {
    std::vector<std::uint32_t>& ring = attempt.ring;
    ring.insert(ring.end(), attempt.outside.begin(), attempt.outside.end());
    ring.insert(ring.end(), also.begin(), also.end());
    const std::size_t merged_before = attempt.merged.size();
    std::vector<Border>& border = border_;
    // The border edge leaving point v (border sorted by `from`, each point once), or
    // border.size().
    const auto leaving = [&](Index v) {
      const auto it = std::lower_bound(border.begin(), border.end(), v,
                                       [](const Border& e, Index from) { return e.from < from; });
      return it != border.end() && it->from == v ? static_cast<std::size_t>(it - border.begin())
                                                 : border.size();
    };
    std::uint32_t outer = 0;      // the longest of the border's loops
    std::size_t outer_start = 0;  // and an edge of it
    for (int pass = 0;; ++pass) {
      std::sort(ring.begin(), ring.end());
      ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
      attempt.merged.resize(merged_before);
      if (!trace_border(attempt, holes, dead, max_edges)) return Widening::stopped;
      // Points the border passes twice: their fans join the ring.
      std::sort(border.begin(), border.end(),
                [](const Border& a, const Border& b) { return a.from < b.from; });
      pinched_.clear();
      for (std::size_t k = 1; k < border.size(); ++k) {
        if (border[k].from == border[k - 1].from) pinched_.push_back(border[k].from);
      }
      if (!pinched_.empty()) {
        if (pass == kMaxWidenPasses) return Widening::stopped;
        for (const Index v : pinched_) {
          const Vec3f& p = grid_.point(v);
          cells.for_each_near(p, p, [&](std::uint32_t t, const detail::Box&) {
            const Triangle& tri = triangles_[t];
            if (!dead[t] && std::find(tri.begin(), tri.end(), v) != tri.end()) ring.push_back(t);
          });
        }
        continue;
      }
      // The triangles outside the ring's border edges, among those near it.
      detail::Box box{grid_.point(border[0].from), grid_.point(border[0].from)};
      for (const Border& e : border) box = detail::enclose(box, grid_.point(e.from));
      cells.for_each_near(box.lo, box.hi, [&](std::uint32_t t, const detail::Box&) {
        if (dead[t] || attempt.in_ring(t)) return;
        const Triangle& tri = triangles_[t];
        for (Border& e : border) {
          if (e.outside == kNoIndex && std::find(tri.begin(), tri.end(), e.from) != tri.end() &&
              std::find(tri.begin(), tri.end(), e.to) != tri.end()) {
            e.outside = t;
          }
        }
      });
      // The border's loops: each edge goes on by the edge leaving its end.
      border_loop_.assign(border.size(), kNoIndex);
      std::uint32_t loops = 0, outer_edges = 0;
      for (std::size_t start = 0; start < border.size(); ++start) {
        if (border_loop_[start] != kNoIndex) continue;
        std::uint32_t edges = 0;
        std::size_t k = start;
        do {
          // No triangle outside among those filed: a filling of this round.
          if (border[k].outside == kNoIndex) return Widening::met_filling;
          border_loop_[k] = loops;
          ++edges;
          k = leaving(border[k].to);
          if (k == border.size() || (k != start && border_loop_[k] != kNoIndex)) {
            return Widening::stopped;
          }
        } while (k != start);
        if (edges > outer_edges) outer = loops, outer_edges = edges, outer_start = start;
        ++loops;
      }
      if (loops == 1) break;
      if (pass == kMaxWidenPasses) return Widening::stopped;
      for (std::size_t k = 0; k < border.size(); ++k) {
        if (border_loop_[k] != outer) ring.push_back(border[k].outside);
      }
    }
    // The loop, chained from the outer loop's first edge.
    attempt.loop.clear();
    attempt.outside.clear();
    attempt.around.clear();
    std::size_t k = outer_start;
    do {
      const Border& e = border[k];
      attempt.add_edge(e.from, e.outside, facing_normal(e.outside));
      k = leaving(e.to);
    } while (k != outer_start);
    return Widening::widened;
  }

  // The border of the attempt's ring and holes (border_, unordered): ring edges with a triangle
  // outside the ring, and the edges of holes the ring reaches, which join the attempt (merged).
  // Also lists the edges inside (inner_edges). False where widen gives up.
  bool trace_border(Attempt& attempt, const HoleIndex& holes, const std::vector<std::uint8_t>& dead,
                    std::size_t max_edges) {
    ring_edges_.clear();
    for (const std::uint32_t r : attempt.ring) {
      if (dead[r]) return false;
      const Triangle tri = facing(r);
      for (int k = 0; k < 3; ++k) {
        if (!fillable(tri[k])) return false;
        const Index u = tri[k], v = tri[(k + 1) % 3];
        ring_edges_.push_back({edge_key(u, v), Border{v, u, kNoIndex}});
      }
    }
    std::sort(ring_edges_.begin(), ring_edges_.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    border_.clear();
    attempt.inner_edges.clear();
    for (std::size_t a = 0, b = 0; a < ring_edges_.size(); a = b) {
      while (b < ring_edges_.size() && ring_edges_[b].first == ring_edges_[a].first) ++b;
      const Border& e = ring_edges_[a].second;
      attempt.inner_edges.push_back(ring_edges_[a].first);
      if (b - a == 2) continue;
      if (triangles_on(e.from, e.to) == 2) {
        border_.push_back(e);
        continue;
      }
      const std::uint32_t h = holes.find(e.from, e.to);
      if (h == kNoIndex) return false;
      const std::uint32_t hole = holes.loop_of[h];
      if (std::find(attempt.merged.begin(), attempt.merged.end(), hole) != attempt.merged.end()) {
        continue;
      }
      if (!holes.is_hole[hole] || holes.taken[hole]) return false;
      attempt.merged.push_back(hole);
    }
    for (std::size_t m = 1; m < attempt.merged.size(); ++m) {
      for (const std::uint32_t h : holes.edges_of(attempt.merged[m])) {
        const OpenEdge& e = holes.open[h];
        if (dead[e.triangle]) return false;
        if (!attempt.in_ring(e.triangle)) border_.push_back({e.from, e.to, e.triangle});
      }
    }
    std::sort(attempt.inner_edges.begin(), attempt.inner_edges.end());
    return border_.size() >= 3 && border_.size() <= max_edges;
  }

  // Per open edge, the open edge its hole's loop goes on by: out of the point it leads to, the
  // first edge counter-clockwise (about the fans' mean normal) from the direction back along
  // it. Every point has as many open edges in as out (one each per open fan), so pairing them
  // in angular order makes each edge out the successor of exactly one edge in, and the loops
  // partition the open edges.
  std::vector<std::uint32_t> next_open_edges(std::span<const OpenEdge> open) {
    const std::uint32_t n = grid_.size();
    std::vector<std::uint32_t> next(open.size(), kNoIndex);
    // Open edges grouped by the point they leave and by the point they reach.
    std::vector<std::uint32_t> out_begin(std::size_t{n} + 1, 0), in_begin(std::size_t{n} + 1, 0);
    for (const OpenEdge& e : open) ++out_begin[e.from + 1], ++in_begin[e.to + 1];
    for (std::uint32_t i = 0; i < n; ++i) {
      out_begin[i + 1] += out_begin[i];
      in_begin[i + 1] += in_begin[i];
    }
    std::vector<std::uint32_t> outs(open.size()), ins(open.size());
    {
      std::vector<std::uint32_t> out_at(out_begin.begin(), out_begin.end() - 1);
      std::vector<std::uint32_t> in_at(in_begin.begin(), in_begin.end() - 1);
      for (std::uint32_t h = 0; h < open.size(); ++h) {
        outs[out_at[open[h].from]++] = h;
        ins[in_at[open[h].to]++] = h;
      }
    }
    std::vector<std::pair<double, std::uint32_t>> around;  // angle, edge (in: high bit set)
    for (std::uint32_t v = 0; v < n; ++v) {
      const std::uint32_t o0 = out_begin[v], o1 = out_begin[v + 1];
      const std::uint32_t i0 = in_begin[v], i1 = in_begin[v + 1];
      if (o1 - o0 != i1 - i0) continue;  // not consistently facing: the loops through v stop
      if (o1 - o0 == 1) {
        next[ins[i0]] = outs[o0];
        continue;
      }
      // Directions away from v projected into the plane of the fans' mean normal.
      const Vec3 p = grid_.position(v);
      Vec3 normal{0, 0, 0};
      for (std::uint32_t k = o0; k < o1; ++k)
        normal = normal + facing_normal(open[outs[k]].triangle);
      for (std::uint32_t k = i0; k < i1; ++k)
        normal = normal + facing_normal(open[ins[k]].triangle);
      normal = normalized(normal);
      Vec3 x_axis{1, 0, 0};
      if (std::abs(normal.x) > 0.9) x_axis = {0, 1, 0};
      x_axis = normalized(cross(cross(normal, x_axis), normal));
      const Vec3 y_axis = cross(normal, x_axis);
      const auto angle_of = [&](Index w) {
        const Vec3 d = grid_.position(w) - p;
        return std::atan2(dot(d, y_axis), dot(d, x_axis));
      };
      around.clear();
      for (std::uint32_t k = o0; k < o1; ++k)
        around.push_back({angle_of(open[outs[k]].to), outs[k]});
      for (std::uint32_t k = i0; k < i1; ++k) {
        around.push_back({angle_of(open[ins[k]].from), ins[k] | 0x80000000u});
      }
      std::sort(around.begin(), around.end());
      // Each edge in, in angular order, takes the first edge out after it counter-clockwise
      // that no edge in has taken.
      const std::size_t m = around.size();
      for (std::size_t a = 0; a < m; ++a) {
        if (!(around[a].second & 0x80000000u)) continue;
        for (std::size_t b = 1; b < m; ++b) {
          std::pair<double, std::uint32_t>& cand = around[(a + b) % m];
          if (cand.second & 0xC0000000u) continue;  // an edge in, or an edge out taken
          next[around[a].second & 0x7FFFFFFFu] = cand.second;
          cand.second |= 0x40000000u;
          break;
        }
      }
    }
    // A loop through a point whose edges could not be paired is not followed.
    for (std::uint32_t h = 0; h < open.size(); ++h) {
      if (next[h] == kNoIndex) next[h] = h;
    }
    return next;
  }

  Vec3 facing_normal(std::uint32_t t) {
    const Triangle tri = facing(t);
    const Vec3 a = grid_.position(tri[0]);
    return normalized(cross(grid_.position(tri[1]) - a, grid_.position(tri[2]) - a));
  }

  // Whether a triangle filling a hole stays clear of the context points, crosses none of the
  // grown triangles near the loop (loop_near_) and repeats none (the loop around a lone triangle
  // that touches the rest at a corner is a loop of its own).
  bool fill_fits(const Triangle& t) {
    const detail::Box box = detail::box_of(grid_.points(), t);
    // A sliver (no circumball) first: the crossing tests below never see one.
    Ball ball;
    if (!detail::padded_circumball(grid_.position(t[0]), grid_.position(t[1]), grid_.position(t[2]),
                                   ball)) {
      return false;
    }
    // Neighbours side by side with the candidate are mostly settled by its planes, built once
    // a near triangle's box overlaps its box.
    std::optional<SeparatingPlanes> planes;
    const auto blocks = [&](std::uint32_t place) {
      const Triangle& o = triangles_[loop_near_.index[place]];
      if (!planes) planes.emplace(positions_.planes(t));
      if (positions_.separate(*planes, o)) return false;
      if (std::is_permutation(o.begin(), o.end(), t.begin())) return true;
      return positions_.cross(t, o);
    };
    // The triangle that refused the last candidate is asked first: where the surface folds over
    // a hole, one grown triangle refuses most of the candidates across it.
    if (last_blocker_ < loop_near_.size() && loop_near_.overlaps(last_blocker_, box) &&
        blocks(last_blocker_)) {
      return false;
    }
    for (const std::uint32_t i : loop_near_.overlapping(box)) {
      if (i != last_blocker_ && blocks(i)) {
        last_blocker_ = i;
        return false;
      }
    }
    // Points this run may not use (a seam's context: tiles still to come) must not lie in the
    // triangle's circumball: the surface may yet be meshed over them. Asked last: four in five
    // candidates are refused above, most by the last blocker alone.
    bool covers_context = false;
    if (!growable_.empty()) {
      grid_.for_each_in_ball(ball.centre, std::sqrt(ball.radius2), [&](std::uint32_t j, double) {
        covers_context = covers_context || (!growable(j) && !fillable(j));
      });
    }
    return !covers_context;
  }

  // A survey of what refuses a hole's first filling: lists in folded_over_ every triangle near
  // the loop (loop_near_) that triangle t crosses, and returns whether there is one. Once such a
  // triangle has no corner on the loop (loop_), the hole is not under a fold of its corners'
  // fans: off_the_fans_ is set, and every later triangle is refused unasked, so that the survey
  // ends soon (a loop edge with no triangle left ends it).
  bool survey_crossings(const Triangle& t) {
    if (off_the_fans_) return true;
    const detail::Box box = detail::box_of(grid_.points(), t);
    const SeparatingPlanes planes = positions_.planes(t);
    const std::size_t before = folded_over_.size();
    for (const std::uint32_t place : loop_near_.overlapping(box)) {
      const Triangle& other = triangles_[loop_near_.index[place]];
      if (positions_.separate(planes, other) || !positions_.cross(t, other)) continue;
      if (std::none_of(other.begin(), other.end(), [&](Index v) {
            return std::find(loop_.begin(), loop_.end(), v) != loop_.end();
          })) {
        off_the_fans_ = true;
        return true;
      }
      folded_over_.push_back(loop_near_.index[place]);
    }
    return folded_over_.size() > before;
  }

  // Whether the survey found the hole under a fold: every triangle that crosses a candidate of
  // its first filling (folded_over_) is of a loop point's fan, and not all are across the loop's
  // edges. Sorts and dedups them.
  bool folded_over(const Attempt& attempt) {
    std::sort(folded_over_.begin(), folded_over_.end());
    folded_over_.erase(std::unique(folded_over_.begin(), folded_over_.end()), folded_over_.end());
    return !off_the_fans_ && !std::all_of(folded_over_.begin(), folded_over_.end(), [&](auto t) {
      return std::find(attempt.outside.begin(), attempt.outside.end(), t) != attempt.outside.end();
    });
  }

  // Fillings of neighbouring holes may cross each other: the later filling of each crossing
  // pair goes whole, and its hole opens again as it was (its ring back, where no filling has
  // taken an edge of it since). Fillings start at triangle `first_fill`.
  void remove_crossing_fills(std::uint32_t first_fill, std::vector<std::uint8_t>& dead) {
    if (triangles_.size() > first_fill) {
      const std::span<const Triangle> fills =
          std::span<const Triangle>(triangles_).subspan(first_fill);
      const auto pairs = detail::TriangleCells(grid_.points(), fills).crossing_pairs(positions_);
      for (const auto& [first, second] : pairs) {
        const FillRecord& earlier = fill_records_[fill_loop_[first]];
        const FillRecord& later = fill_records_[fill_loop_[second]];
        if (dead[earlier.first] || dead[later.first]) continue;
        unfill(later, dead);
      }
    }
    fill_loop_.clear();
    fill_records_.clear();
    fill_rings_.clear();
  }

  // Takes a filling off the mesh and puts its ring back if every edge of the ring still has room.
  void unfill(const FillRecord& record, std::vector<std::uint8_t>& dead) {
    for (std::uint32_t t = record.first; t < record.first + record.count; ++t) {
      dead[t] = kUnlinked;
      const Triangle& tri = triangles_[t];
      for (int k = 0; k < 3; ++k) edges_.remove(tri[k], tri[(k + 1) % 3]);
    }
    const std::span<const std::uint32_t> ring(fill_rings_.data() + record.ring_begin,
                                              record.ring_size);
    std::vector<std::uint64_t> ring_edges;
    for (const std::uint32_t r : ring) {
      const Triangle& tri = triangles_[r];
      for (int k = 0; k < 3; ++k) ring_edges.push_back(edge_key(tri[k], tri[(k + 1) % 3]));
    }
    std::sort(ring_edges.begin(), ring_edges.end());
    for (std::size_t a = 0, b = 0; a < ring_edges.size(); a = b) {
      while (b < ring_edges.size() && ring_edges[b] == ring_edges[a]) ++b;
      const auto u = static_cast<Index>(ring_edges[a] >> 32), v = static_cast<Index>(ring_edges[a]);
      if (triangles_on(u, v) + (b - a) > 2) return;
    }
    for (const std::uint32_t r : ring) {
      dead[r] = 0;
      const Triangle& tri = triangles_[r];
      for (int k = 0; k < 3; ++k) edges_.add(tri[k], tri[(k + 1) % 3], r);
    }
  }

  // How many triangles edge {u, v} has: 0, 1 or 2.
  int triangles_on(Index u, Index v) const {
    const std::uint32_t value = edges_.find(u, v);
    return value == EdgeMap::kMissing ? 0 : (value & EdgeMap::kClosed) ? 2 : 1;
  }

  // Processes front edges until the front is empty (docs/algorithm.md §4).
  void drain() {
    FrontEdge e;
    while (!queue_.empty()) {
      const int level = queue_.pop(e);
      // Processing an edge is bound by memory latency: start loading what the edge after the
      // next one will look up first.
      if (const FrontEdge* next = queue_.peek(1)) {
        edges_.prefetch(next->a, next->b);
        __builtin_prefetch(&triangles_[next->triangle]);
        if (next->cand != kNoIndex) {  // re-validated by try_add
          __builtin_prefetch(&state_[next->cand]);
          edges_.prefetch(next->a, next->cand);
          edges_.prefetch(next->cand, next->b);
        }
      }
      if (edges_.find(e.a, e.b) != e.triangle) continue;  // closed meanwhile
      if (e.cand != kNoIndex) {
        if (!interior(e.cand) && try_add(e, e.cand)) continue;
        if (retries_ > 0) {
          retry(e, e.cand);
          stall(e);
          continue;
        }
      }
      // One candidate per edge: if it cannot join, the edge stays open unless a neighbour
      // closes it. (Retrying with the next-best point was measured to give worse meshes: the
      // Gabriel point's ball is then no longer empty.)
      const Candidate c = find_candidate(e);
      if (c.point == kNoIndex) {
        stall(e);
        continue;
      }
      int priority = c.priority;
      const std::uint32_t on_ap = used(c.point) ? edges_.find(e.a, c.point) : EdgeMap::kMissing;
      const std::uint32_t on_pb = used(c.point) ? edges_.find(c.point, e.b) : EdgeMap::kMissing;
      // Touching a used point only at the vertex starts a second fan there: wait until the
      // last level, when the fronts around it may have joined it along an edge instead.
      if (used(c.point) && on_ap == EdgeMap::kMissing && on_pb == EdgeMap::kMissing) {
        priority = last_priority_;
      }
      if (priority > level) {
        queue_.push(priority, {e.a, e.b, e.triangle, c.point});
        continue;
      }
      if (!try_add(e, c.point, on_ap, on_pb)) {
        if (retries_ > 0) retry(e, c.point);
        stall(e);
      }
    }
  }

  // An edge leaving the queue without a triangle of its own (on a seam, the retries may still
  // have given it one): close_three_edge_gaps looks at it if it is still open by then.
  void stall(const FrontEdge& e) {
    if (options_.close_gaps) stalled_.push_back({e.a, e.b, e.triangle, kNoIndex});
  }

  // Stitching only: between two meshes that are already fixed, an edge whose Gabriel point
  // cannot join would leave a crack, so the next points in Gabriel order are tried.
  void retry(const FrontEdge& e, Index failed) {
    excluded_.assign(1, failed);
    for (int k = 0; k < retries_; ++k) {
      const Candidate c = find_candidate(e);
      if (c.point == kNoIndex) break;
      const bool was_used = used(c.point);
      const std::uint32_t on_ap = was_used ? edges_.find(e.a, c.point) : EdgeMap::kMissing;
      const std::uint32_t on_pb = was_used ? edges_.find(c.point, e.b) : EdgeMap::kMissing;
      // Only a point that is free or closes the crack along an edge: not a second fan.
      const bool fan = was_used && on_ap == EdgeMap::kMissing && on_pb == EdgeMap::kMissing;
      if (!fan && try_add(e, c.point, on_ap, on_pb)) break;
      excluded_.push_back(c.point);
    }
    excluded_.clear();
  }

  // The point to grow edge e onto, and its priority value m*(radius level) + flatness level.
  // The search balls of all levels pass through a and b with centres on the same ray, so on the
  // growing side each contains the one before: the level-1 ball is gathered first (most edges
  // stop there), then, if needed, the level-2 ball, then the largest once, and each level
  // filters its pool by its own ball. The level-2 pool is the part of the largest ball's that the
  // level-2 ball (widened far beyond rounding) holds, so every level sees the same candidates as
  // if all were filtered from the largest ball; it saves gathering the largest ball (eight times
  // the volume) for the edges that stop at level 2.
  Candidate find_candidate(const FrontEdge& e) {
    const Index c = apex(triangles_[e.triangle], e.a, e.b);
    const Vec3 a = grid_.position(e.a), b = grid_.position(e.b), pc = grid_.position(c);
    const Vec3 n = normalized(cross(b - a, pc - a));
    const Vec3 ab = b - a;
    const double len = norm(ab);
    if (len >= radius_cap_) return {};
    const Vec3 mid = (a + b) * 0.5;
    const Vec3 out = normalized(cross(ab, n));
    const double base = std::max(len, radius_floor_);
    auto ball_of = [&](int level, double& along) {
      const double radius =
          std::min(options_.radius_steps[static_cast<std::size_t>(level)] * base, radius_cap_);
      along = std::sqrt(std::max(radius * radius - 0.25 * len * len, 0.0));
      return radius;
    };
    // The level's ball, its radius widened by `widen` (relative, plus as much of the coordinates'
    // size, scaled by 1e-5, for the rounding of the centre).
    auto query_of = [&](int level, double widen) {
      double along = 0;
      const double radius = ball_of(level, along);
      const double size = std::abs(mid.x) + std::abs(mid.y) + std::abs(mid.z);
      return HashGrid::BallQuery(grid_, mid + out * along,
                                 radius * (1 + widen) + widen * 1e-5 * size);
    };
    // within: the query whose pool this one's is part of, or nullptr.
    auto gather = [&](const HashGrid::BallQuery& query, const HashGrid::BallQuery* within) {
      pool_.clear();
      grid_.for_each_in_ball(query, [&](std::uint32_t j, double) {
        if (j == e.a || j == e.b || j == c || interior(j)) return;
        if (std::find(excluded_.begin(), excluded_.end(), j) != excluded_.end()) return;
        const Vec3 q = grid_.position(j);
        const Vec3 d = q - mid;
        const double ahead = dot(d, out);
        if (ahead <= 0) return;
        if (within && !within->visits(grid_, j)) return;
        pool_.push_back({{q, norm2(d), j}, ahead});
      });
    };
    gather(query_of(0, 0), nullptr);
    bool split = false;
    for (int level = 0; level < levels_; ++level) {
      if (level == 1) {
        double unused = 0;
        split = levels_ > 2 && ball_of(1, unused) < ball_of(levels_ - 1, unused);
        const HashGrid::BallQuery largest = query_of(levels_ - 1, 0);
        if (split) {
          gather(query_of(1, 1e-7), &largest);
        } else {
          gather(largest, nullptr);
        }
      } else if (level == 2 && split) {
        gather(query_of(levels_ - 1, 0), nullptr);
      }
      double along = 0;
      ball_of(level, along);
      // Inside this level's ball: |q - mid - along*out|^2 <= radius^2 = along^2 + len^2/4.
      cand_.clear();
      for (const PoolPoint& q : pool_) {
        if (q.walk.dist2 - 2 * along * q.ahead <= 0.25 * len * len) cand_.push_back(q.walk);
      }
      const Index p = cand_.empty() ? kNoIndex : gabriel_walk(a, b, cand_);
      if (p == kNoIndex) continue;
      const Vec3 n_new = normalized(cross(a - b, grid_.position(p) - b));
      const int flat = flatness(std::clamp(dot(n, n_new), -1.0, 1.0));
      if (flat >= 0 && growable(p)) return {p, level * flat_levels_ + flat};
      // A fold, or context the run may not use: the next level may find another point.
    }
    return {};
  }

  // The flatness level of a new triangle whose normal makes an angle beta = acos(cos_beta) with
  // its front triangle's: beta in max_fold_ / flat_levels_ steps, -1 beyond max_fold_ (a fold).
  // Decided by comparing cos_beta with the steps' cosines; only within 1e-9 of one, far beyond
  // the rounding of either side, does acos decide, so the level is always the one acos gives.
  int flatness(double cos_beta) const {
    int flat = 0;
    bool near = bound_cos_.empty();
    for (const double bound : bound_cos_) {
      near |= !(std::abs(cos_beta - bound) > 1e-9);
      flat += cos_beta < bound;
    }
    if (!near) return flat == flat_levels_ ? -1 : flat;
    const double beta = std::acos(cos_beta);
    if (!(beta <= max_fold_)) return -1;
    return std::min(flat_levels_ - 1, static_cast<int>(beta / max_fold_ * flat_levels_));
  }

  // Adds triangle (b, a, p) across front edge a->b if the Point-Edge Map allows it: no edge gets
  // a third triangle, shared edges are traversed in opposite directions, no duplicate, no fold.
  bool try_add(const FrontEdge& e, Index p) {
    if (!used(p)) return try_add(e, p, EdgeMap::kMissing, EdgeMap::kMissing);
    return try_add(e, p, edges_.find(e.a, p), edges_.find(p, e.b));
  }

  // The same with the Point-Edge Map entries of (a, p) and (p, b) already looked up.
  bool try_add(const FrontEdge& e, Index p, std::uint32_t on_ap, std::uint32_t on_pb) {
    if (interior(p) || !growable(p) || p == e.a || p == e.b) return false;
    if (on_ap != EdgeMap::kMissing) {
      if ((on_ap & EdgeMap::kClosed) || on_ap == e.triangle) return false;
    }
    if (on_pb != EdgeMap::kMissing) {
      if ((on_pb & EdgeMap::kClosed) || on_pb == e.triangle) return false;
      if (on_pb == on_ap) return false;
    }
    // No sliver: every triangle the grower makes has a circumball, so the guard's argument
    // covers them all.
    const Vec3 a = grid_.position(e.a), b = grid_.position(e.b);
    if (!has_circumball(a, b, grid_.position(p))) return false;
    const Vec3 n_new = normalized(cross(a - b, grid_.position(p) - b));
    // A neighbour sharing the edge in the same direction will face the other way once the
    // groups are joined: compare with its normal reversed.
    if (on_ap != EdgeMap::kMissing) {
      const double facing = traverses(triangles_[on_ap], p, e.a) ? 1.0 : -1.0;
      if (facing * dot(n_new, normal_of(on_ap)) < cos_max_fold_) return false;
    }
    if (on_pb != EdgeMap::kMissing) {
      const double facing = traverses(triangles_[on_pb], e.b, p) ? 1.0 : -1.0;
      if (facing * dot(n_new, normal_of(on_pb)) < cos_max_fold_) return false;
    }
    // No triangle that crosses one made before (docs/algorithm.md, "No crossing triangles").
    if (guard_->crosses({e.b, e.a, p}, triangles_)) return false;
    if (!join_groups(e.triangle, e.a, p, e.b, on_ap, on_pb)) return false;
    if (used(p) && on_ap == EdgeMap::kMissing && on_pb == EdgeMap::kMissing) {
      second_fans_.push_back(p);
    }
    add_triangle(e.b, e.a, p, group_[e.triangle], flip_[e.triangle]);
    return true;
  }

  // A seed triangle (docs/algorithm.md §2): point i, its nearest unused neighbour, and the nearest
  // third point that makes a Gabriel triangle whose circumcircle's cylinder is not cut by points
  // on both sides (it does not bridge a thin part).
  bool try_seed(Index i) {
    const double spacing = std::max(grid_.spacing(), 1e-30);
    const auto unused = [&](std::uint32_t j) { return !used(j) && growable(j); };
    const Index q = grid_.nearest(i, 4.0 * spacing, unused);
    if (q == kNoIndex) return false;
    const Vec3 p0 = grid_.position(i), p1 = grid_.position(q);
    const Vec3 mid = (p0 + p1) * 0.5;
    const double radius = options_.seed_ball * norm(p1 - p0);
    near_.clear();
    grid_.for_each_in_ball(mid, radius, [&](std::uint32_t j, double d2) {
      near_.push_back({d2, j});
    });
    std::sort(near_.begin(), near_.end());
    for (const auto& candidate : near_) {
      const std::uint32_t r = candidate.second;  // a named variable: lambdas below capture it
      if (r == i || r == q || used(r) || !growable(r)) continue;
      const Vec3 p2 = grid_.position(r);
      Ball ball;
      if (!circumball(p0, p1, p2, ball)) continue;
      const double tol = 1e-6 * ball.radius2;
      const double reach = std::sqrt(ball.radius2) + norm(ball.centre - mid);
      bool gabriel = true;
      const auto check = [&](std::uint32_t j) {
        if (j == i || j == q || j == r) return;
        if (norm2(grid_.position(j) - ball.centre) < ball.radius2 - tol) gabriel = false;
      };
      if (reach <= radius) {
        for (const auto& nj : near_) check(nj.second);
      } else {
        grid_.for_each_in_ball(ball.centre, std::sqrt(ball.radius2),
                               [&](std::uint32_t j, double) { check(j); });
      }
      if (!gabriel) continue;
      const Vec3 n = normalized(cross(p1 - p0, p2 - p0));
      const double slack = 0.2 * std::sqrt(ball.radius2);
      bool above = false, below = false;
      for (const auto& nj : near_) {
        const std::uint32_t j = nj.second;
        if (j == i || j == q || j == r) continue;
        const Vec3 d = grid_.position(j) - ball.centre;
        const double h = dot(d, n);
        if (norm2(d) - h * h >= ball.radius2) continue;  // outside the cylinder
        above |= h > slack;
        below |= h < -slack;
      }
      if (above && below) continue;
      if (guard_->crosses({i, q, r}, triangles_)) continue;
      add_triangle(i, q, r, groups_.add(), 0);
      return true;
    }
    return false;
  }

  const HashGrid& grid_;
  const MeshOptions& options_;
  const std::span<const std::uint8_t> growable_;
  const std::span<const std::uint8_t> fillable_;
  const int retries_;
  const int levels_;
  const int flat_levels_;
  std::vector<Triangle> triangles_;  // the preloaded ones first
  std::size_t preloaded_ = 0;        // triangles_[0, preloaded_) were loaded before the run
  std::vector<std::uint32_t> preload_index_;  // per loaded triangle: its place in the context
  // Loaded triangles a filling replaced, with their groups as they were.
  struct RemovedPreload {
    std::uint32_t index, group;
    std::uint8_t flip;
  };
  std::vector<RemovedPreload> removed_preload_;
  std::vector<std::uint32_t> group_;     // per triangle: its orientation group
  std::vector<std::uint8_t> flip_;       // per triangle: its parity within the group
  std::vector<std::uint32_t> piece_of_;  // pieces(), while !pieces_stale_
  bool pieces_stale_ = true;
  ParityUnionFind groups_;
  std::vector<Index> second_fans_;
  EdgeMap edges_;
  std::vector<std::uint8_t> seed_tried_;
  const detail::CrossingPositions positions_;   // what crossings are judged on
  std::optional<detail::CrossingGuard> guard_;  // while growth lasts
  // Per point: kUsed once it is a corner, plus the number of open edges at it; one array, so
  // that the interior test of every point a search ball holds is a single load.
  static constexpr std::uint32_t kUsed = 0x80000000u;
  // A mark for compact: off the Point-Edge Map already (any other non-zero mark: removed with its
  // edges).
  static constexpr std::uint8_t kUnlinked = 2;
  // How many times a widened border may take in more triangles before it is one loop through
  // each of its points once: the fans of points it passes twice, the pockets it closes around.
  // More made no difference on the shared scans (16: raw-bunny 674 holes against 675).
  static constexpr int kMaxWidenPasses = 8;
  // How far (in spacings) from the surface a point that a widened filling or a scrap leaves out
  // may lie: noise spreads a scan's points over a layer a few spacings thick, and the points
  // farther out stay vertices.
  static constexpr double kMaxLeftOutDistance = 3;
  std::vector<std::uint32_t> state_;
  std::vector<FrontEdge> stalled_;  // edges that left the queue without a triangle (stall())
  std::vector<FillRecord> fill_records_;
  std::vector<std::uint32_t> fill_rings_;
  std::vector<std::uint32_t> fill_loop_;  // per filling triangle: its FillRecord
  std::uint64_t used_count_ = 0;
  BucketQueue<FrontEdge> queue_;
  const int last_priority_;
  const double max_fold_;
  const double cos_max_fold_;
  std::vector<double> bound_cos_;  // cos(k * max_fold_ / flat_levels_), k = 1..flat_levels_
  const double radius_floor_;
  const double radius_cap_;
  // Scratch, reused across edges so the inner loop does not allocate.
  std::vector<PoolPoint> pool_;
  std::vector<WalkPoint> cand_;
  std::vector<Index> excluded_;  // points a retried edge has already failed with
  std::vector<std::pair<double, std::uint32_t>> near_;
  // fill_holes: the grown triangles near the loop being filled, and their boxes a coordinate per
  // array, so that the overlap tests run four or more at a time.
  struct NearTriangles {
    std::vector<std::uint32_t> index;
    std::vector<float> lo_x, lo_y, lo_z, hi_x, hi_y, hi_z;
    std::vector<std::uint8_t> overlap;  // overlapping's scratch
    std::vector<std::uint32_t> hits;    // and its answer

    void clear() {
      index.clear();
      for (auto* v : {&lo_x, &lo_y, &lo_z, &hi_x, &hi_y, &hi_z}) v->clear();
    }
    void push(std::uint32_t t, const detail::Box& b) {
      index.push_back(t);
      lo_x.push_back(b.lo.x), lo_y.push_back(b.lo.y), lo_z.push_back(b.lo.z);
      hi_x.push_back(b.hi.x), hi_y.push_back(b.hi.y), hi_z.push_back(b.hi.z);
    }
    std::size_t size() const { return index.size(); }
    // Whether the box at place p overlaps `box`.
    bool overlaps(std::size_t p, const detail::Box& box) const {
      return box.lo.x <= hi_x[p] && lo_x[p] <= box.hi.x && box.lo.y <= hi_y[p] &&
             lo_y[p] <= box.hi.y && box.lo.z <= hi_z[p] && lo_z[p] <= box.hi.z;
    }
    // The places whose boxes overlap `box`, in order: the tests without a branch (about one box
    // in five overlaps, in no order a branch predictor could learn), then the list without one.
    std::span<const std::uint32_t> overlapping(const detail::Box& box) {
      const std::size_t end = size();
      overlap.resize(end);
      hits.resize(end);
      // Local pointers: a store through a byte pointer could alias the vectors' own, which
      // would keep the compiler from running the tests several at a time.
      const float *lx = lo_x.data(), *ly = lo_y.data(), *lz = lo_z.data();
      const float *hx = hi_x.data(), *hy = hi_y.data(), *hz = hi_z.data();
      std::uint8_t* out = overlap.data();
      std::uint32_t* listed = hits.data();
      const Vec3f lo = box.lo, hi = box.hi;
      for (std::size_t i = 0; i < end; ++i) {
        out[i] = static_cast<std::uint8_t>((lo.x <= hx[i]) & (lx[i] <= hi.x) & (lo.y <= hy[i]) &
                                           (ly[i] <= hi.y) & (lo.z <= hz[i]) & (lz[i] <= hi.z));
      }
      std::size_t count = 0;
      for (std::size_t i = 0; i < end; ++i) {
        listed[count] = static_cast<std::uint32_t>(i);
        count += out[i];
      }
      return {listed, count};
    }
  };
  NearTriangles loop_near_;
  std::vector<std::uint32_t> folded_over_;  // survey_crossings: what crosses a hole's first filling
  bool off_the_fans_ = false;               // and whether one of them is of no loop point's fan
  std::uint32_t last_blocker_ = kNoIndex;   // fill_fits: the place in loop_near_ that refused last
  // An edge of a widened hole's border, as the triangle outside it faces (outside, once found).
  struct Border {
    Index from, to;
    std::uint32_t outside;
  };
  std::vector<Border> border_;              // widen's scratch
  std::vector<std::uint32_t> border_loop_;  // widen's: per border edge, its loop
  std::vector<std::pair<std::uint64_t, Border>> ring_edges_;
  std::vector<Index> pinched_;
  std::vector<Index> loop_;  // try_fill's loop and normals
  std::vector<Vec3> around_;
};

}  // namespace

GrowResult grow_mesh(const HashGrid& grid, const MeshOptions& options, const GrowContext& context) {
  return Grower(grid, options, context).run(context);
}

}  // namespace g2s
