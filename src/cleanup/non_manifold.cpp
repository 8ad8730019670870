// Non-manifold vertex removal, after Di Angelo & Giaccari (2011) §4.1; docs/algorithm.md §5.
// Instead of the paper's dynamic edge queue we walk each vertex's star directly: the star's
// triangles are linked across the edges they share at the vertex, giving its fans; when there is
// more than one, the closed fan (type I) or the largest (type II) is kept and the others are
// deleted. Deleting can split a fan at the deleted triangles' other corners, so those go back on
// a worklist. Each deletion is final, so the total work is linear in the mesh size.
#include <algorithm>
#include <bit>
#include <functional>
#include <memory>
#include <numeric>

#include "cleanup/cleanup.hpp"
#include "common/union_find.hpp"

namespace g2s {
namespace {

// A triangle seen from one corner: its index and its two other corners, in its order.
struct Corner {
  std::uint32_t triangle;
  Index u, w;
};

// Per vertex, its triangles in index order. Near a few suspects only the stars examined are
// built, in one batch (the queued vertices with every corner of their triangles, since a
// deletion queues those) by passes over the triangles that mostly only read; a vertex outside
// it, or many suspects (one in 64 vertices), has every star built at once.
class Stars {
 public:
  Stars(std::span<const Triangle> triangles, std::size_t vertex_count, std::size_t suspects)
      : triangles_(triangles),
        state_(vertex_count, kUnbuilt),
        begin_(std::make_unique_for_overwrite<std::uint32_t[]>(vertex_count)),
        end_(std::make_unique_for_overwrite<std::uint32_t[]>(vertex_count)) {
    if (suspects * 64 > vertex_count) build_all();
  }

  // v's star; `queued` are the vertices to be examined after it.
  std::span<const Corner> of(Index v, std::span<const Index> queued) {
    if (state_[v] != kBuilt) {
      if (batched_) {
        build_all();
      } else {
        batched_ = true;
        std::vector<Index> batch{v};
        for (const Index u : queued) {
          if (state_[u] == kUnbuilt) batch.push_back(u);
        }
        build(batch);
        std::vector<Index> ring;
        for (const Index u : batch) {
          for (std::uint32_t k = begin_[u]; k < end_[u]; ++k) {
            for (const Index x : {corners_[k].u, corners_[k].w}) {
              if (state_[x] != kUnbuilt) continue;
              state_[x] = kWanted;
              ring.push_back(x);
            }
          }
        }
        build(ring);
      }
    }
    return {corners_.data() + begin_[v], corners_.data() + end_[v]};
  }

 private:
  enum : std::uint8_t { kUnbuilt, kWanted, kBuilt };

  void build_all() {
    std::vector<Index> rest;
    for (std::size_t u = 0; u < state_.size(); ++u) {
      if (state_[u] == kUnbuilt) rest.push_back(static_cast<Index>(u));
    }
    build(rest);
  }

  // Two passes over the triangles: the stars' sizes, then their corners, appended in triangle
  // order.
  void build(std::span<const Index> batch) {
    if (batch.empty()) return;
    for (const Index u : batch) state_[u] = kWanted, end_[u] = 0;
    for (const Triangle& t : triangles_) {
      for (const Index u : t) {
        if (state_[u] == kWanted) ++end_[u];
      }
    }
    auto at = static_cast<std::uint32_t>(corners_.size());
    for (const Index u : batch) {
      begin_[u] = at;
      at += end_[u];
      end_[u] = begin_[u];  // the fill position, until the second pass ends
    }
    corners_.resize(at);
    for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
      const Triangle& c = triangles_[t];
      if (state_[c[0]] == kWanted) corners_[end_[c[0]]++] = {t, c[1], c[2]};
      if (state_[c[1]] == kWanted) corners_[end_[c[1]]++] = {t, c[0], c[2]};
      if (state_[c[2]] == kWanted) corners_[end_[c[2]]++] = {t, c[0], c[1]};
    }
    for (const Index u : batch) state_[u] = kBuilt;
  }

  std::span<const Triangle> triangles_;
  std::vector<std::uint8_t> state_;
  std::unique_ptr<std::uint32_t[]> begin_, end_;
  std::vector<Corner> corners_;
  bool batched_ = false;
};

}  // namespace

// finished empty: every vertex is finished.
NonManifoldReport mark_non_manifold_fans(std::span<const Triangle> triangles,
                                         std::size_t vertex_count, std::span<const Index> suspects,
                                         std::span<const std::uint8_t> finished,
                                         std::vector<std::uint8_t>& dead,
                                         std::vector<Index>& deferred) {
  NonManifoldReport report;
  const std::size_t nt = triangles.size();
  dead.assign(nt, 0);
  if (suspects.empty()) return report;
  Stars stars(triangles, vertex_count, suspects.size());
  // Suspects are examined in index order whatever order they arose in.
  // The work list is popped from the back, so it runs from the largest index down. Suspects
  // come with many repeats (every corner of every removed triangle): where sorting them would
  // cost more than reading a flag per vertex, the flags put them in order.
  std::vector<std::uint8_t> queued(vertex_count, 0);
  std::vector<Index> work;
  if (suspects.size() * std::bit_width(suspects.size()) > vertex_count) {
    for (const Index v : suspects) queued[v] = 1;
    for (std::size_t v = vertex_count; v-- > 0;) {
      if (queued[v]) work.push_back(static_cast<Index>(v));
    }
  } else {
    work.assign(suspects.begin(), suspects.end());
    std::sort(work.begin(), work.end(), std::greater<Index>());
    work.erase(std::unique(work.begin(), work.end()), work.end());
    for (const Index v : work) queued[v] = 1;
  }

  // Scratch for one star.
  std::vector<Corner> tris;
  std::vector<std::uint32_t> parent, size;
  std::vector<std::pair<Index, std::uint32_t>> spokes;  // (other corner, local triangle)
  std::vector<std::uint8_t> open;

  while (!work.empty()) {
    const Index v = work.back();
    work.pop_back();
    queued[v] = 0;
    tris.clear();
    for (const Corner& corner : stars.of(v, work)) {
      if (!dead[corner.triangle]) tris.push_back(corner);
    }
    if (tris.size() < 2) continue;
    const auto m = static_cast<std::uint32_t>(tris.size());
    parent.resize(m);
    std::iota(parent.begin(), parent.end(), 0u);
    spokes.clear();
    for (std::uint32_t l = 0; l < m; ++l) {
      spokes.push_back({tris[l].u, l});
      spokes.push_back({tris[l].w, l});
    }
    std::sort(spokes.begin(), spokes.end());
    for (std::size_t k = 0; k + 1 < spokes.size(); ++k) {
      if (spokes[k].first == spokes[k + 1].first) {
        parent[find_root(parent, spokes[k].second)] = find_root(parent, spokes[k + 1].second);
      }
    }
    // Fans: size and closedness (closed when every spoke of the fan is shared by two triangles).
    size.assign(m, 0);
    open.assign(m, 0);
    for (std::uint32_t l = 0; l < m; ++l) ++size[find_root(parent, l)];
    for (std::size_t k = 0; k < spokes.size(); ++k) {
      const bool shared = (k > 0 && spokes[k - 1].first == spokes[k].first) ||
                          (k + 1 < spokes.size() && spokes[k + 1].first == spokes[k].first);
      if (!shared) open[find_root(parent, spokes[k].second)] = 1;
    }
    std::uint32_t fans = 0, keep = kNoIndex;
    for (std::uint32_t l = 0; l < m; ++l) {
      if (find_root(parent, l) != l) continue;
      ++fans;
      // Prefer closed, then larger; ties keep the fan met first (lowest triangle index).
      if (keep == kNoIndex || (open[keep] && !open[l]) ||
          (open[keep] == open[l] && size[l] > size[keep])) {
        keep = l;
      }
    }
    if (fans < 2) continue;
    ++report.vertices_fixed;
    for (std::uint32_t l = 0; l < m; ++l) {
      if (find_root(parent, l) == keep) continue;
      dead[tris[l].triangle] = 1;
      ++report.triangles_removed;
      for (Index w : {tris[l].u, tris[l].w}) {
        if (queued[w]) continue;
        queued[w] = 1;
        if (finished.empty() || finished[w] == 1) {
          work.push_back(w);
        } else if (finished[w] == 0) {
          deferred.push_back(w);  // stays queued: deferred once
        } else {
          ++report.vertices_unjudged;
        }
      }
    }
  }

  return report;
}

}  // namespace g2s
