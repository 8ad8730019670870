// Defects counted in stride (include/g2s/stream_stats.hpp): the tiled pipeline hands on a
// triangle as soon as it is final and says when a vertex will get no more triangles, so every
// count of compute_stats can be taken vertex by vertex while the mesh streams out, instead of
// reading the written file back (on the 6M-point alpine scan that read-back was a quarter of the
// run and more than doubled the peak memory).
//
// What is held: the vertices not yet done, welded by their position as the file stores it, each
// with its star as wedges (per triangle: the corners after and before it, and its group), so
// judging a vertex reads only its own record. When a vertex is done its star is complete, so its
// fans are judged and its edges counted; an edge has the same triangles seen from either end, so
// edge classes are counted at both ends and halved. Holes and components need union-find over
// vertices; a forest over the open vertices is enough, since a done vertex joins nothing more,
// and it is rebuilt over the open vertices' roots whenever it has grown to twice their number.
// Orientation conflicts between two groups depend on the flips decided at the end: those edges
// are tallied per pair of groups and settled in finish().
#include "g2s/stream_stats.hpp"

#include <algorithm>
#include <bit>
#include <unordered_map>
#include <vector>

#include "common/id_map.hpp"
#include "common/union_find.hpp"

namespace g2s {
namespace {

// The stream sees each triangle once and keeps no geometry index: crossings are g2s stats' work.
MeshStats crossings_not_counted() {
  MeshStats stats;
  stats.has_crossings = false;
  return stats;
}

// Union-find over the open vertices: nodes are added as vertices open; compact() keeps only the
// roots that open vertices still reach. merges counts the unions that joined two sets.
struct OpenUnionFind {
  std::vector<std::uint32_t> parent;
  std::uint64_t merges = 0;

  std::uint32_t add() {
    const auto node = static_cast<std::uint32_t>(parent.size());
    parent.push_back(node);
    return node;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a == b) return;
    parent[std::max(a, b)] = std::min(a, b);
    ++merges;
  }
  // Renumbers the nodes `live` points to as their roots, 0, 1, 2, ... (one node per set).
  void compact(std::span<std::uint32_t* const> live) {
    IdMap renumbered(2 * live.size() + 16);
    std::vector<std::uint32_t> roots;
    for (std::uint32_t* node : live) {
      const std::uint32_t root = find_root(parent, *node);
      *node = renumbered.insert(root, static_cast<std::uint32_t>(roots.size()));
      if (*node == roots.size()) roots.push_back(root);
    }
    parent.resize(roots.size());
    for (std::uint32_t k = 0; k < roots.size(); ++k) parent[k] = k;
    parent.shrink_to_fit();
  }
};

// Bit patterns with -0.0 folded onto +0.0 (compute_stats welds by exact equality).
std::uint64_t key_bits(double d) {
  return std::bit_cast<std::uint64_t>(d == 0.0 ? 0.0 : d);
}

std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 31;
  x *= 0x7fb5d329728ea185ULL;
  x ^= x >> 27;
  x *= 0x81dadef4bc2dd44dULL;
  return x ^ (x >> 33);
}

// One edge {v, w} seen from v while judging v's star.
struct EdgeGroup {
  std::uint32_t w;      // the other end, as a vertex number
  std::uint32_t count;  // star triangles on the edge
  std::uint32_t first;  // the first two of them (positions in the star)
  std::uint32_t second;
  std::uint32_t out;  // how many run v -> w
};

}  // namespace

struct StreamStats::Impl {
  // An open vertex: welded by position; `rep` is the number of its first vertex, the name its
  // triangles use.
  // A triangle as seen from one of its corners: the corners after and before it, and its group.
  struct Wedge {
    std::uint32_t next;
    std::uint32_t prev;
    std::uint32_t group;
  };
  static constexpr std::uint32_t kInlineWedges = 9;  // most stars fit (G2S: about 6)
  struct Open {
    double xyz[3];
    std::uint32_t rep;
    std::uint32_t refs;  // vertex numbers welded here and not yet done
    std::uint32_t component;
    std::uint32_t border;    // node in the boundary-edge graph
    std::uint32_t wedges;    // its star's triangles so far
    std::uint32_t overflow;  // the list holding wedges past the inline ones (kNoIndex: none)
    Wedge inline_wedges[kInlineWedges];
  };
  Impl(MeshSink& sink, bool rounded) : next(sink), float_positions(rounded) {}

  MeshSink& next;
  bool float_positions;
  MeshStats stats = crossings_not_counted();
  bool complete = true;
  std::uint32_t numbered = 0;  // vertices given so far

  std::vector<Open> open;
  std::vector<std::uint32_t> free_open;
  std::size_t open_count = 0;
  IdMap open_of;                      // vertex number -> open vertex
  std::vector<std::uint32_t> welder;  // position hash table of open vertices (kNoIndex: empty)
  std::size_t welder_mask = 0;
  std::vector<std::vector<Wedge>> overflow;  // large stars' further wedges
  std::vector<std::uint32_t> free_overflow;
  OpenUnionFind components;
  OpenUnionFind borders;
  std::uint64_t boundary_merges = 0;
  // Edge classes counted at both ends of each edge (halved in finish()).
  std::uint64_t boundary_ends = 0;
  std::uint64_t conflict_ends = 0;
  std::uint64_t non_manifold_ends = 0;
  // Two-triangle edges between different groups, per (lower group << 32 | higher): how many run
  // the same way and how many opposite ways before the flips.
  std::unordered_map<std::uint64_t, std::array<std::uint64_t, 2>> group_pairs;

  // Per-star scratch.
  std::vector<Wedge> star;
  std::vector<EdgeGroup> groups;
  std::vector<std::uint32_t> group_next, group_prev, fan;
  std::vector<std::uint8_t> fan_open;

  std::size_t home(const double* p) const {
    return mix(key_bits(p[0]) * 0x9e3779b97f4a7c15ULL ^
               mix(key_bits(p[1]) + 0x632be59bd9b4e019ULL) ^ key_bits(p[2])) &
           welder_mask;
  }
  bool same_position(const double* a, const double* b) const {
    return key_bits(a[0]) == key_bits(b[0]) && key_bits(a[1]) == key_bits(b[1]) &&
           key_bits(a[2]) == key_bits(b[2]);
  }
  void welder_insert(std::uint32_t o) {
    if (2 * (open_count + 1) > welder.size()) {
      std::vector<std::uint32_t> old = std::exchange(welder, {});
      welder.assign(std::max<std::size_t>(64, 2 * old.size()), kNoIndex);
      welder_mask = welder.size() - 1;
      for (std::uint32_t e : old) {
        if (e != kNoIndex) welder_place(e);
      }
    }
    welder_place(o);
  }
  void welder_place(std::uint32_t o) {
    std::size_t k = home(open[o].xyz);
    while (welder[k] != kNoIndex) k = (k + 1) & welder_mask;
    welder[k] = o;
  }
  std::uint32_t welder_find(const double* p) const {
    if (welder.empty()) return kNoIndex;
    for (std::size_t k = home(p);; k = (k + 1) & welder_mask) {
      if (welder[k] == kNoIndex || same_position(open[welder[k]].xyz, p)) return welder[k];
    }
  }
  // Backward-shift deletion, as IdMap does.
  void welder_erase(std::uint32_t o) {
    std::size_t hole = home(open[o].xyz);
    while (welder[hole] != o) hole = (hole + 1) & welder_mask;
    for (std::size_t k = (hole + 1) & welder_mask; welder[k] != kNoIndex;
         k = (k + 1) & welder_mask) {
      const std::size_t want = home(open[welder[k]].xyz);
      if (((k - want) & welder_mask) >= ((k - hole) & welder_mask)) {
        welder[hole] = welder[k];
        hole = k;
      }
    }
    welder[hole] = kNoIndex;
  }

  void add_vertex(const double* given) {
    const std::uint32_t number = numbered++;
    double p[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = float_positions ? static_cast<double>(static_cast<float>(given[k])) : given[k];
    }
    std::uint32_t o = welder_find(p);
    if (o == kNoIndex) {
      if (free_open.empty()) {
        o = static_cast<std::uint32_t>(open.size());
        open.emplace_back();
      } else {
        o = free_open.back();
        free_open.pop_back();
      }
      Open& v = open[o];
      std::copy_n(p, 3, v.xyz);
      v.rep = number;
      v.refs = 0;
      v.wedges = 0;
      v.overflow = kNoIndex;
      v.component = components.add();
      v.border = borders.add();
      ++open_count;
      welder_insert(o);
    }
    ++open[o].refs;
    if (components.parent.size() > 2 * open_count + 4096) compact();
    open_of.insert(number, o);
  }

  // Rebuilds both forests over the roots the open vertices reach.
  void compact() {
    std::vector<std::uint32_t*> component_nodes, border_nodes;
    for (Open& v : open) {
      if (v.refs == 0) continue;  // a free slot
      component_nodes.push_back(&v.component);
      border_nodes.push_back(&v.border);
    }
    components.compact(component_nodes);
    borders.compact(border_nodes);
  }

  // Two equal welded corners, or a cross product of exactly zero (compute_stats' test, on the
  // positions as written).
  bool degenerate(const std::array<std::uint32_t, 3>& o) const {
    if (o[0] == o[1] || o[1] == o[2] || o[0] == o[2]) return true;
    const double* a = open[o[0]].xyz;
    const double* b = open[o[1]].xyz;
    const double* c = open[o[2]].xyz;
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    return u[1] * v[2] - u[2] * v[1] == 0.0 && u[2] * v[0] - u[0] * v[2] == 0.0 &&
           u[0] * v[1] - u[1] * v[0] == 0.0;
  }

  void for_each_wedge(const Open& v, const auto& visit) const {
    const std::uint32_t held = std::min(v.wedges, kInlineWedges);
    for (std::uint32_t k = 0; k < held; ++k) visit(v.inline_wedges[k]);
    if (v.overflow != kNoIndex) {
      for (const Wedge& w : overflow[v.overflow]) visit(w);
    }
  }

  void add_wedge(Open& v, const Wedge& w) {
    if (v.wedges < kInlineWedges) {
      v.inline_wedges[v.wedges++] = w;
      return;
    }
    if (v.overflow == kNoIndex) {
      if (free_overflow.empty()) {
        v.overflow = static_cast<std::uint32_t>(overflow.size());
        overflow.emplace_back();
      } else {
        v.overflow = free_overflow.back();
        free_overflow.pop_back();
      }
    }
    overflow[v.overflow].push_back(w);
    ++v.wedges;
  }

  // A later copy of a vertex set already in the star of its first corner.
  bool duplicate(const Triangle& rep, std::uint32_t first) const {
    bool found = false;
    for_each_wedge(open[first], [&](const Wedge& w) {
      found =
          found || (w.next == rep[1] && w.prev == rep[2]) || (w.next == rep[2] && w.prev == rep[1]);
    });
    return found;
  }

  void add_triangle(const Triangle& numbers, std::uint32_t group) {
    ++stats.triangles;
    std::array<std::uint32_t, 3> o{};
    for (int k = 0; k < 3; ++k) {
      o[k] = open_of.find(numbers[k]);
      if (o[k] == IdMap::kMissing) {
        complete = false;  // a corner already done: the counts can no longer be exact
        return;
      }
    }
    if (degenerate(o)) {
      ++stats.degenerate_triangles;
      return;
    }
    const Triangle rep{open[o[0]].rep, open[o[1]].rep, open[o[2]].rep};
    if (duplicate(rep, o[0])) {
      ++stats.duplicate_triangles;
      return;
    }
    for (int k = 0; k < 3; ++k) add_wedge(open[o[k]], {rep[(k + 1) % 3], rep[(k + 2) % 3], group});
    components.unite(open[o[0]].component, open[o[1]].component);
    components.unite(open[o[0]].component, open[o[2]].component);
  }

  void done(std::uint32_t number) {
    const std::uint32_t o = open_of.find(number);
    if (o == IdMap::kMissing) return;
    if (number != open[o].rep) open_of.erase(number);
    if (--open[o].refs == 0) judge(o);
  }

  // v's star is complete: count its fans and its edges, then forget it. Every edge is seen from
  // both ends with the same triangles, so edge counts are taken at both ends and halved at the
  // end; only a boundary edge looks up its other end, to join the two in the boundary graph
  // while both are open.
  void judge(std::uint32_t o) {
    Open& vertex = open[o];
    star.clear();
    for_each_wedge(vertex, [&](const Wedge& w) { star.push_back(w); });
    if (!star.empty()) ++stats.vertices;
    groups.clear();
    group_next.clear();
    group_prev.clear();
    auto touch = [&](std::uint32_t w, std::uint32_t i, std::uint32_t outgoing) {
      std::uint32_t g = 0;
      while (g < groups.size() && groups[g].w != w) ++g;
      if (g == groups.size()) groups.push_back({w, 0, i, 0, 0});
      EdgeGroup& e = groups[g];
      if (e.count == 1) e.second = i;
      ++e.count;
      e.out += outgoing;
      return g;
    };
    for (std::uint32_t i = 0; i < star.size(); ++i) {
      group_next.push_back(touch(star[i].next, i, 1));
      group_prev.push_back(touch(star[i].prev, i, 0));
    }
    const std::size_t k = star.size();
    fan.resize(k);
    for (std::uint32_t i = 0; i < k; ++i) fan[i] = i;
    for (const EdgeGroup& e : groups) {
      if (e.count == 1) {
        ++boundary_ends;
        const std::uint32_t w = open_of.find(e.w);
        if (w != IdMap::kMissing) {  // else joined when that end was judged
          const std::uint64_t before = borders.merges;
          borders.unite(vertex.border, open[w].border);
          boundary_merges += borders.merges - before;
        }
      } else if (e.count == 2) {
        const std::uint32_t a = find_root(fan, e.first), b = find_root(fan, e.second);
        if (a != b) fan[std::max(a, b)] = std::min(a, b);
        const std::uint32_t g1 = star[e.first].group, g2 = star[e.second].group;
        const bool same_way = e.out != 1;
        if (g1 == g2) {
          conflict_ends += same_way ? 1 : 0;
        } else {
          const std::uint64_t pair = std::uint64_t{std::min(g1, g2)} << 32 | std::max(g1, g2);
          ++group_pairs[pair][same_way ? 0 : 1];
        }
      } else {
        ++non_manifold_ends;
      }
    }
    fan_open.assign(k, 0);
    std::size_t fans = 0;
    for (std::uint32_t i = 0; i < k; ++i) {
      const std::uint32_t root = find_root(fan, i);
      if (root == i) ++fans;
      if (groups[group_next[i]].count != 2 || groups[group_prev[i]].count != 2) fan_open[root] = 1;
    }
    if (fans > 1) {
      ++stats.non_manifold_vertices;
      bool any_closed = false;
      for (std::uint32_t i = 0; i < k; ++i)
        any_closed = any_closed || (fan[i] == i && !fan_open[i]);
      ++(any_closed ? stats.non_manifold_vertices_type1 : stats.non_manifold_vertices_type2);
    }
    if (vertex.overflow != kNoIndex) {
      overflow[vertex.overflow].clear();
      free_overflow.push_back(vertex.overflow);
    }
    open_of.erase(vertex.rep);
    welder_erase(o);
    vertex.refs = 0;
    free_open.push_back(o);
    --open_count;
  }

  void finish(std::span<const std::uint8_t> flip) {
    for (std::uint32_t o = 0; o < open.size(); ++o) {
      if (open[o].refs > 0) {
        open[o].refs = 1;
        judge(o);
      }
    }
    for (const auto& [pair, ways] : group_pairs) {
      const auto g1 = static_cast<std::uint32_t>(pair >> 32), g2 = static_cast<std::uint32_t>(pair);
      const bool one_flipped = (g1 < flip.size() && flip[g1]) != (g2 < flip.size() && flip[g2]);
      conflict_ends += one_flipped ? ways[1] : ways[0];
    }
    stats.boundary_edges = boundary_ends / 2;
    stats.orientation_conflicts = conflict_ends / 2;
    stats.non_manifold_edges = non_manifold_ends / 2;
    stats.holes = stats.boundary_edges - boundary_merges;
    stats.components = stats.vertices - components.merges;
  }

  std::uint64_t bytes() const {
    std::uint64_t overflowing = 0;
    for (const std::vector<Wedge>& list : overflow) overflowing += list.capacity() * sizeof(Wedge);
    return open.capacity() * sizeof(Open) + overflowing +
           (welder.capacity() + free_open.capacity() + components.parent.capacity() +
            borders.parent.capacity()) *
               sizeof(std::uint32_t) +
           open_of.size() * 16 + group_pairs.size() * 48;
  }
};

StreamStats::StreamStats(MeshSink& next, bool float_positions)
    : impl_(std::make_unique<Impl>(next, float_positions)) {}
StreamStats::~StreamStats() = default;

void StreamStats::vertex(Index id, const double xyz[3]) {
  impl_->add_vertex(xyz);
  impl_->next.vertex(id, xyz);
}

void StreamStats::triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                           std::uint32_t group) {
  impl_->add_triangle(corners, group);
  impl_->next.triangle(corners, xyz, group);
}

void StreamStats::vertex_done(std::uint32_t vertex) {
  impl_->done(vertex);
  impl_->next.vertex_done(vertex);
}

void StreamStats::finish(std::span<const std::uint8_t> flip) {
  impl_->finish(flip);
  impl_->next.finish(flip);
}

const MeshStats& StreamStats::stats() const {
  return impl_->stats;
}
bool StreamStats::complete() const {
  return impl_->complete;
}
std::uint64_t StreamStats::peak_bytes() const {
  return impl_->bytes();
}

}  // namespace g2s
