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
//
// Cost: the counter runs on the stitcher's thread, once per vertex and triangle, so its lookups
// are laid out for the stream's locality (bench/results/2026-11-24-summary-cost.md): vertex
// numbers map to records through a window of recent numbers, positions weld through a hash
// whose slots follow space, records never move, and most stars (no two triangles sharing the
// corner after, or the one before) are judged in one pass without grouping their edges.
#include "g2s/stream_stats.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <memory>
#include <unordered_map>
#include <utility>
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

// Open-addressing table of 64-bit slots (key in the high half, value in the low half; all ones:
// empty), linear probing and backward-shift deletion. The home slot is a function of the key
// alone, given by the user, so probing and deleting never read anything outside the table.
class SlotTable {
 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  static std::uint64_t slot(std::uint32_t key, std::uint32_t value) {
    return std::uint64_t{key} << 32 | value;
  }
  static std::uint32_t key_of(std::uint64_t s) { return static_cast<std::uint32_t>(s >> 32); }
  static std::uint32_t value_of(std::uint64_t s) { return static_cast<std::uint32_t>(s); }

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return slots_.capacity(); }
  std::size_t mask() const { return mask_; }
  const std::vector<std::uint64_t>& slots() const { return slots_; }

  // Calls visit(slot) for the slots from home(key) until an empty one or visit returns true;
  // returns the slot visit accepted, or kEmpty.
  std::uint64_t probe(std::size_t home, const auto& accept) const {
    if (slots_.empty()) return kEmpty;
    for (std::size_t k = home & mask_;; k = (k + 1) & mask_) {
      if (slots_[k] == kEmpty || accept(slots_[k])) return slots_[k];
    }
  }
  // Adds a slot whose key is not there yet; `home` maps a key to its home slot (before masking).
  void insert(std::uint64_t s, const auto& home) {
    if (2 * (size_ + 1) > slots_.size()) {
      std::vector<std::uint64_t> old = std::exchange(slots_, {});
      slots_.assign(std::max<std::size_t>(64, 2 * old.size()), kEmpty);
      mask_ = slots_.size() - 1;
      for (std::uint64_t e : old) {
        if (e != kEmpty) place(e, home);
      }
    }
    place(s, home);
    ++size_;
  }
  // Removes slot `s` (there).
  void erase(std::uint64_t s, const auto& home) {
    std::size_t hole = home(key_of(s)) & mask_;
    while (slots_[hole] != s) hole = (hole + 1) & mask_;
    for (std::size_t k = (hole + 1) & mask_; slots_[k] != kEmpty; k = (k + 1) & mask_) {
      const std::size_t want = home(key_of(slots_[k])) & mask_;
      if (((k - want) & mask_) >= ((k - hole) & mask_)) {
        slots_[hole] = slots_[k];
        hole = k;
      }
    }
    slots_[hole] = kEmpty;
    --size_;
  }

 private:
  void place(std::uint64_t s, const auto& home) {
    std::size_t k = home(key_of(s)) & mask_;
    while (slots_[k] != kEmpty) k = (k + 1) & mask_;
    slots_[k] = s;
  }
  std::vector<std::uint64_t> slots_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

// Vertex number -> open vertex, for numbers inserted in increasing order. The last kWindow
// numbers sit directly at number % kWindow: triangles use recent vertices, so almost every lookup
// is one read of a table that stays in cache. A number still open when the window passes it (a
// vertex on a seam waiting for the next tile) moves to a hash table.
class NumberMap {
 public:
  static constexpr std::uint32_t kMissing = 0xFFFFFFFFu;
  std::uint32_t find(std::uint32_t number) const {
    if (recent_.empty()) return kMissing;
    const std::uint64_t e = recent_[number & kWindowMask];
    if (e != SlotTable::kEmpty && SlotTable::key_of(e) == number) return SlotTable::value_of(e);
    const std::uint64_t s = older_.probe(
        home(number), [number](std::uint64_t o) { return SlotTable::key_of(o) == number; });
    return s == SlotTable::kEmpty ? kMissing : SlotTable::value_of(s);
  }
  void insert(std::uint32_t number, std::uint32_t value) {
    if (recent_.empty()) recent_.assign(kWindow, SlotTable::kEmpty);
    std::uint64_t& e = recent_[number & kWindowMask];
    if (e != SlotTable::kEmpty) older_.insert(e, home);
    e = SlotTable::slot(number, value);
  }
  void erase(std::uint32_t number) {
    if (recent_.empty()) return;
    std::uint64_t& e = recent_[number & kWindowMask];
    if (e != SlotTable::kEmpty && SlotTable::key_of(e) == number) {
      e = SlotTable::kEmpty;
      return;
    }
    const std::uint64_t s = older_.probe(
        home(number), [number](std::uint64_t o) { return SlotTable::key_of(o) == number; });
    if (s != SlotTable::kEmpty) older_.erase(s, home);
  }
  std::uint64_t bytes() const {
    return (recent_.capacity() + older_.capacity()) * sizeof(std::uint64_t);
  }

 private:
  static constexpr std::uint32_t kWindow = 1u << 17;
  static constexpr std::uint32_t kWindowMask = kWindow - 1;
  static std::size_t home(std::uint32_t number) {
    return static_cast<std::size_t>((std::uint64_t{number} * 0x9E3779B97F4A7C15ull) >> 20);
  }
  std::vector<std::uint64_t> recent_;
  SlotTable older_;
};

// One edge {v, w} seen from v while judging v's star.
struct EdgeGroup {
  std::uint32_t w;      // the other end, as a vertex number
  std::uint32_t count;  // star triangles on the edge
  std::uint32_t first;  // the first two of them (positions in the star)
  std::uint32_t second;
  std::uint32_t out;  // how many run v -> w
};

// A triangle as seen from one of its corners: the corners after and before it, and its group.
struct Wedge {
  std::uint32_t next;
  std::uint32_t prev;
  std::uint32_t group;
};

// What judging stars adds up. Edge classes are counted at both ends of each edge (halved at the
// end).
struct StarCounts {
  std::uint64_t vertices = 0;  // with a triangle
  std::uint64_t non_manifold_vertices = 0;
  std::uint64_t non_manifold_vertices_type1 = 0;
  std::uint64_t non_manifold_vertices_type2 = 0;
  std::uint64_t boundary_ends = 0;
  std::uint64_t conflict_ends = 0;
  std::uint64_t non_manifold_ends = 0;

  StarCounts& operator+=(const StarCounts& o) {
    vertices += o.vertices;
    non_manifold_vertices += o.non_manifold_vertices;
    non_manifold_vertices_type1 += o.non_manifold_vertices_type1;
    non_manifold_vertices_type2 += o.non_manifold_vertices_type2;
    boundary_ends += o.boundary_ends;
    conflict_ends += o.conflict_ends;
    non_manifold_ends += o.non_manifold_ends;
    return *this;
  }
};

// Judges complete stars (one vertex's triangles, as wedges): its fans and its edges. For each
// boundary edge, boundary(w) is called with its other end; for each two-triangle edge between
// two groups, pair(g1, g2, opposite) with g1 < g2 (whether the two run opposite ways; the
// conflict is settled once the groups' flips are known). Scratch arrays are kept between stars.
class StarJudge {
 public:
  template <class Boundary, class Pair>
  void judge(std::span<const Wedge> s, StarCounts& c, Boundary&& boundary, Pair&& pair) {
    if (!s.empty()) ++c.vertices;
    if (!judge_simple_star(s, c, boundary, pair)) judge_star(s, c, boundary, pair);
  }

 private:
  // The common star, judged in one pass: no two of its triangles share their next corner or
  // their previous one. Then each edge holds one or two of them, two running opposite ways, and
  // "triangle j follows triangle i" (i's next corner is j's previous one) links them into
  // chains (open fans, starting at a triangle that follows none) and cycles (closed fans). The
  // counts are those judge_star gives; false (nothing counted) for any other star.
  static constexpr std::size_t kSimpleStar = 16;
  template <class Boundary, class Pair>
  static bool judge_simple_star(std::span<const Wedge> s, StarCounts& c, Boundary& boundary,
                                Pair& pair) {
    const std::size_t k = s.size();
    if (k > kSimpleStar) return false;
    std::array<std::uint32_t, kSimpleStar> follower;  // kNoIndex: none (a boundary edge)
    std::array<bool, kSimpleStar> preceded;
    std::fill_n(follower.begin(), k, kNoIndex);
    std::fill_n(preceded.begin(), k, false);
    for (std::uint32_t i = 0; i < k; ++i) {
      for (std::uint32_t j = i + 1; j < k; ++j) {
        if (s[i].next == s[j].next || s[i].prev == s[j].prev) return false;
        if (s[i].next == s[j].prev) {
          follower[i] = j;
          preceded[j] = true;
        }
        if (s[j].next == s[i].prev) {
          follower[j] = i;
          preceded[i] = true;
        }
      }
    }
    std::size_t links = 0, starts = 0;
    for (std::size_t i = 0; i < k; ++i) {
      if (follower[i] == kNoIndex) {
        boundary(s[i].next);
      } else {
        ++links;
        const std::uint32_t g1 = s[i].group, g2 = s[follower[i]].group;
        if (g1 != g2) pair(std::min(g1, g2), std::max(g1, g2), true);
      }
      if (!preceded[i]) {
        ++starts;
        boundary(s[i].prev);
      }
    }
    c.boundary_ends += 2 * (k - links);
    // The triangles left over after walking the chains from their starts form the cycles.
    std::array<bool, kSimpleStar> seen{};
    for (std::size_t i = 0; i < k; ++i) {
      if (preceded[i]) continue;
      for (std::uint32_t t = static_cast<std::uint32_t>(i); t != kNoIndex; t = follower[t]) {
        seen[t] = true;
      }
    }
    std::size_t cycles = 0;
    for (std::size_t i = 0; i < k; ++i) {
      if (seen[i]) continue;
      ++cycles;
      for (std::uint32_t t = static_cast<std::uint32_t>(i); !seen[t]; t = follower[t]) {
        seen[t] = true;
      }
    }
    const std::size_t fans = starts + cycles;
    if (fans > 1) {
      ++c.non_manifold_vertices;
      ++(cycles > 0 ? c.non_manifold_vertices_type1 : c.non_manifold_vertices_type2);
    }
    return true;
  }

  // Any star: its edges grouped by their other end, fans as unions of triangles across
  // two-triangle edges.
  template <class Boundary, class Pair>
  void judge_star(std::span<const Wedge> s, StarCounts& c, Boundary& boundary, Pair& pair) {
    groups_.clear();
    group_next_.clear();
    group_prev_.clear();
    auto touch = [&](std::uint32_t w, std::uint32_t i, std::uint32_t outgoing) {
      std::uint32_t g = 0;
      while (g < groups_.size() && groups_[g].w != w) ++g;
      if (g == groups_.size()) groups_.push_back({w, 0, i, 0, 0});
      EdgeGroup& e = groups_[g];
      if (e.count == 1) e.second = i;
      ++e.count;
      e.out += outgoing;
      return g;
    };
    for (std::uint32_t i = 0; i < s.size(); ++i) {
      group_next_.push_back(touch(s[i].next, i, 1));
      group_prev_.push_back(touch(s[i].prev, i, 0));
    }
    const std::size_t k = s.size();
    fan_.resize(k);
    for (std::uint32_t i = 0; i < k; ++i) fan_[i] = i;
    for (const EdgeGroup& e : groups_) {
      if (e.count == 1) {
        ++c.boundary_ends;
        boundary(e.w);
      } else if (e.count == 2) {
        const std::uint32_t a = find_root(fan_, e.first), b = find_root(fan_, e.second);
        if (a != b) fan_[std::max(a, b)] = std::min(a, b);
        const std::uint32_t g1 = s[e.first].group, g2 = s[e.second].group;
        const bool same_way = e.out != 1;
        if (g1 == g2) {
          c.conflict_ends += same_way ? 1 : 0;
        } else {
          pair(std::min(g1, g2), std::max(g1, g2), !same_way);
        }
      } else {
        ++c.non_manifold_ends;
      }
    }
    fan_open_.assign(k, 0);
    std::size_t fans = 0;
    for (std::uint32_t i = 0; i < k; ++i) {
      const std::uint32_t root = find_root(fan_, i);
      if (root == i) ++fans;
      if (groups_[group_next_[i]].count != 2 || groups_[group_prev_[i]].count != 2) {
        fan_open_[root] = 1;
      }
    }
    if (fans > 1) {
      ++c.non_manifold_vertices;
      bool any_closed = false;
      for (std::uint32_t i = 0; i < k; ++i)
        any_closed = any_closed || (fan_[i] == i && !fan_open_[i]);
      ++(any_closed ? c.non_manifold_vertices_type1 : c.non_manifold_vertices_type2);
    }
  }

  std::vector<EdgeGroup> groups_;
  std::vector<std::uint32_t> group_next_, group_prev_, fan_;
  std::vector<std::uint8_t> fan_open_;
};

// Two equal corners, or a cross product of exactly zero (compute_stats' test, on the positions as
// written).
bool degenerate(const std::array<std::uint32_t, 3>& o, const double (&p)[3][3]) {
  if (o[0] == o[1] || o[1] == o[2] || o[0] == o[2]) return true;
  const double* a = p[0];
  const double* b = p[1];
  const double* c = p[2];
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return u[1] * v[2] - u[2] * v[1] == 0.0 && u[2] * v[0] - u[0] * v[2] == 0.0 &&
         u[0] * v[1] - u[1] * v[0] == 0.0;
}

// Whether a star already holds a triangle on the vertex set {w1, w2} (either way round).
bool holds_triangle(std::span<const Wedge> star, std::uint32_t w1, std::uint32_t w2) {
  for (const Wedge& w : star) {
    if ((w.next == w1 && w.prev == w2) || (w.next == w2 && w.prev == w1)) return true;
  }
  return false;
}

// A position as the file stores it: rounded to float for STL.
void stored_position(const double* given, bool rounded, double* p) {
  for (int k = 0; k < 3; ++k) {
    p[k] = rounded ? static_cast<double>(static_cast<float>(given[k])) : given[k];
  }
}

// A block counted ahead (StreamStats::prepare), in the block's own numbers: every vertex the
// block says is done is judged; the others (held: later triangles will reach them) are handed to
// the counter with their wedges so far, and how the block joins them.
struct BlockCount final : SinkBlockWork {
  std::uint64_t triangles = 0;
  std::uint64_t degenerate = 0;
  std::uint64_t duplicates = 0;
  StarCounts counts;
  // Two-triangle edges between groups, (lower << 32 | higher) with the block's groups, and how
  // many run the same way and how many opposite ways.
  std::vector<std::pair<std::uint64_t, std::array<std::uint64_t, 2>>> pairs;
  std::vector<std::uint32_t> held;        // vertex numbers, increasing
  std::vector<std::uint32_t> held_start;  // per held vertex: its first wedge in held_wedges
  std::vector<Wedge> held_wedges;
  // The unions the block made in the component and boundary forests, less those the counter
  // makes again when it joins the held vertices each set holds (links: pairs of places in held).
  std::uint64_t component_merges = 0;
  std::uint64_t boundary_merges = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> component_links;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary_links;
  std::unique_ptr<SinkBlockWork> next;  // the next sink's work on the block
};

// Pairs each held vertex (held: vertex numbers) with the first held vertex of its set in
// `forest` (one node per vertex of the block); returns the forest's merges less the pairs, which
// the counter makes again when it joins the held vertices.
std::uint64_t held_links(OpenUnionFind& forest, std::span<const std::uint32_t> held,
                         std::vector<std::pair<std::uint32_t, std::uint32_t>>& out) {
  std::vector<std::uint32_t> first(forest.parent.size(), kNoIndex);  // per root: its first held
  for (std::uint32_t h = 0; h < held.size(); ++h) {
    std::uint32_t& f = first[find_root(forest.parent, held[h])];
    if (f == kNoIndex) {
      f = h;
    } else {
      out.emplace_back(f, h);
    }
  }
  return forest.merges - out.size();
}

std::unique_ptr<BlockCount> count_block(const SinkBlock& b, bool rounded) {
  auto out = std::make_unique<BlockCount>();
  const std::size_t n = b.ids.size();
  const std::size_t t_count = b.triangles.size();
  std::vector<std::uint8_t> done(n, 0);
  for (const auto& [t, v] : b.done) done[v] = 1;
  // Each vertex's star, in triangle order (the order the counter adds wedges).
  std::vector<std::uint32_t> start(n + 1, 0);
  for (const Triangle& t : b.triangles) {
    for (Index v : t) ++start[v + 1];
  }
  for (std::size_t v = 0; v < n; ++v) start[v + 1] += start[v];
  std::vector<std::uint32_t> filled(start.begin(), start.end() - 1);
  // Only the slots filled below are read: left uninitialised, the array costs no pass of its own
  // (value-initialising it was half of this function's samples on a clean torus).
  const std::unique_ptr<Wedge[]> wedges = std::make_unique_for_overwrite<Wedge[]>(start[n]);
  OpenUnionFind components, borders;  // over the block's vertices
  for (std::size_t v = 0; v < n; ++v) {
    components.add();
    borders.add();
  }
  out->triangles = t_count;
  for (std::size_t k = 0; k < t_count; ++k) {
    const Triangle& t = b.triangles[k];
    double p[3][3];
    for (int c = 0; c < 3; ++c) stored_position(&b.xyz[3 * std::size_t{t[c]}], rounded, p[c]);
    if (degenerate({t[0], t[1], t[2]}, p)) {
      ++out->degenerate;
      continue;
    }
    if (holds_triangle(std::span(wedges.get() + start[t[0]], filled[t[0]] - start[t[0]]), t[1],
                       t[2])) {
      ++out->duplicates;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      wedges[filled[t[c]]++] = {t[(c + 1) % 3], t[(c + 2) % 3], b.group[k]};
    }
    components.unite(t[0], t[1]);
    components.unite(t[0], t[2]);
  }
  std::unordered_map<std::uint64_t, std::array<std::uint64_t, 2>> pairs;
  StarJudge judge;
  for (std::uint32_t v = 0; v < n; ++v) {
    const std::span<const Wedge> star(wedges.get() + start[v], filled[v] - start[v]);
    if (!done[v]) {
      out->held.push_back(v);
      out->held_start.push_back(static_cast<std::uint32_t>(out->held_wedges.size()));
      out->held_wedges.insert(out->held_wedges.end(), star.begin(), star.end());
      continue;
    }
    judge.judge(
        star, out->counts, [&](std::uint32_t w) { borders.unite(v, w); },
        [&](std::uint32_t g1, std::uint32_t g2, bool opposite) {
          ++pairs[std::uint64_t{g1} << 32 | g2][opposite ? 1 : 0];
        });
  }
  out->held_start.push_back(static_cast<std::uint32_t>(out->held_wedges.size()));
  out->pairs.assign(pairs.begin(), pairs.end());
  std::sort(out->pairs.begin(), out->pairs.end());
  out->component_merges = held_links(components, out->held, out->component_links);
  out->boundary_merges = held_links(borders, out->held, out->boundary_links);
  return out;
}

}  // namespace

struct StreamStats::Impl {
  static constexpr std::uint32_t kInlineWedges = 9;  // most stars fit (G2S: about 6)
  // An open vertex: welded by position; `rep` is the number of its first vertex, the name its
  // triangles use. Two cache lines (the header and the first four wedges in the first): its
  // position is kept apart (`position`), since only a weld key match reads it.
  struct alignas(64) Open {
    std::uint32_t rep;
    std::uint32_t key;       // its weld key
    std::uint32_t wedges;    // its star's triangles so far
    std::uint32_t overflow;  // the list holding wedges past the inline ones (kNoIndex: none)
    Wedge inline_wedges[kInlineWedges];
  };
  Impl(MeshSink& sink, bool rounded, bool distinct)
      : next(sink), float_positions(rounded), welding(!distinct) {}

  MeshSink& next;
  bool float_positions;
  bool welding;  // vertices may share a position: weld them by it
  MeshStats stats = crossings_not_counted();
  bool complete = true;
  std::uint32_t numbered = 0;  // vertices given so far
  std::uint64_t peak = 0;      // bytes() before the forests last shrank

  // The open vertices' records, in chunks that never move (growing copies nothing and holds no
  // spare half), and their union-find nodes apart, so that rebuilding the forests reads only
  // those.
  static constexpr std::uint32_t kChunkBits = 10;
  std::vector<std::unique_ptr<Open[]>> chunks;
  std::uint32_t slots = 0;  // records made so far
  struct Nodes {
    std::uint32_t refs;  // vertex numbers welded here and not yet done (0: a free slot)
    std::uint32_t component;
    std::uint32_t border;  // node in the boundary-edge graph
  };
  std::vector<Nodes> node;
  std::vector<std::array<double, 3>> position;  // as the file stores it
  Open& open(std::uint32_t o) { return chunks[o >> kChunkBits][o & ((1u << kChunkBits) - 1)]; }
  const Open& open(std::uint32_t o) const {
    return chunks[o >> kChunkBits][o & ((1u << kChunkBits) - 1)];
  }
  std::vector<std::uint32_t> free_open;
  std::size_t open_count = 0;
  NumberMap open_of;               // vertex number -> open vertex
  SlotTable welder;                // weld key -> open vertex, over the open vertices
  double inverse_cell_size = 0.0;  // the welder's cells (0: not sized yet)
  double edge_sum = 0.0;           // the first triangles' edges, to size the cells
  std::uint32_t edges_summed = 0;
  static constexpr std::uint32_t kEdgesForCells = 1024;
  std::vector<std::vector<Wedge>> overflow;  // large stars' further wedges
  std::vector<std::uint32_t> free_overflow;
  OpenUnionFind components;
  OpenUnionFind borders;
  std::uint64_t boundary_merges = 0;
  StarCounts counts;
  // Two-triangle edges between different groups, per (lower group << 32 | higher): how many run
  // the same way and how many opposite ways before the flips.
  std::unordered_map<std::uint64_t, std::array<std::uint64_t, 2>> group_pairs;

  std::vector<Wedge> star;  // a large star gathered
  StarJudge star_judge;

  bool same_position(const double* a, const double* b) const {
    return key_bits(a[0]) == key_bits(b[0]) && key_bits(a[1]) == key_bits(b[1]) &&
           key_bits(a[2]) == key_bits(b[2]);
  }
  // The welder's key of a position: 24 bits naming its cell (a cube of side cell_size, or the
  // position itself before the size is known) over 8 bits of the exact position. Vertices near
  // each other in space, which the stream gives near each other in time, share their cell's run
  // of slots, so most probes hit a cache line a neighbour just used.
  std::uint32_t weld_key(const double* p) const {
    double c[3];
    for (int k = 0; k < 3; ++k) {
      const double d = p[k] == 0.0 ? 0.0 : p[k];
      c[k] = inverse_cell_size > 0.0 ? std::floor(d * inverse_cell_size) : d;
    }
    const std::uint64_t cell = mix(key_bits(c[0]) * 0x9e3779b97f4a7c15ULL ^
                                   mix(key_bits(c[1]) + 0x632be59bd9b4e019ULL) ^ key_bits(c[2]));
    const std::uint64_t exact =
        mix(key_bits(p[0]) ^ std::rotl(key_bits(p[1]), 21) ^ std::rotl(key_bits(p[2]), 42));
    return static_cast<std::uint32_t>(cell >> 40) << 8 | static_cast<std::uint32_t>(exact >> 56);
  }
  static std::size_t weld_home(std::uint32_t key) {
    return static_cast<std::size_t>((std::uint64_t{key >> 8} * 0x9E3779B97F4A7C15ull) >> 24 << 3 |
                                    (key & 7));
  }
  std::uint32_t welder_find(const double* p, std::uint32_t key) const {
    const std::uint64_t s = welder.probe(weld_home(key), [&](std::uint64_t e) {
      return SlotTable::key_of(e) == key &&
             same_position(position[SlotTable::value_of(e)].data(), p);
    });
    return s == SlotTable::kEmpty ? kNoIndex : SlotTable::value_of(s);
  }
  void welder_insert(std::uint32_t o, std::uint32_t key) {
    open(o).key = key;
    welder.insert(SlotTable::slot(key, o), weld_home);
  }
  void welder_erase(std::uint32_t o) { welder.erase(SlotTable::slot(open(o).key, o), weld_home); }
  // Sets the welder's cell size from the first triangles' edges (the power of two at or above
  // their mean |dx| + |dy| + |dz|: a few vertices a cell) and rebuilds it; the counts do not
  // depend on it, only the welder's speed.
  void size_cells() {
    const double edge = edge_sum / static_cast<double>(edges_summed);
    if (!(edge > 0.0) || !std::isfinite(edge)) return;
    inverse_cell_size = 1.0 / std::exp2(std::ceil(std::log2(edge)));
    if (!std::isfinite(inverse_cell_size)) inverse_cell_size = 0.0;
    const std::vector<std::uint64_t> old = welder.slots();
    welder = SlotTable();
    for (std::uint64_t e : old) {
      if (e != SlotTable::kEmpty) {
        const std::uint32_t o = SlotTable::value_of(e);
        welder_insert(o, weld_key(position[o].data()));
      }
    }
  }

  // A new open vertex's record: vertex `number`, at position p as stored, no references yet.
  std::uint32_t new_open(std::uint32_t number, const double* p) {
    std::uint32_t o = 0;
    if (free_open.empty()) {
      o = slots++;
      if ((o >> kChunkBits) == chunks.size()) {
        chunks.push_back(std::make_unique_for_overwrite<Open[]>(std::size_t{1} << kChunkBits));
      }
      node.emplace_back();
      position.emplace_back();
    } else {
      o = free_open.back();
      free_open.pop_back();
    }
    Open& v = open(o);
    std::copy_n(p, 3, position[o].begin());
    v.rep = number;
    node[o].refs = 0;
    v.wedges = 0;
    v.overflow = kNoIndex;
    node[o].component = components.add();
    node[o].border = borders.add();
    ++open_count;
    return o;
  }

  void add_vertex(const double* given) {
    const std::uint32_t number = numbered++;
    double p[3];
    stored_position(given, float_positions, p);
    const std::uint32_t key = welding ? weld_key(p) : 0;
    std::uint32_t o = welding ? welder_find(p, key) : kNoIndex;
    if (o == kNoIndex) {
      o = new_open(number, p);
      if (welding) welder_insert(o, key);
    }
    ++node[o].refs;
    if (components.parent.size() > 2 * open_count + 4096) compact();
    open_of.insert(number, o);
  }

  // A vertex of a block held open (not welded: blocks are counted ahead only without welding).
  std::uint32_t add_held(std::uint32_t number, const double* given) {
    double p[3];
    stored_position(given, float_positions, p);
    const std::uint32_t o = new_open(number, p);
    node[o].refs = 1;
    open_of.insert(number, o);
    return o;
  }

  // A block counted ahead: its counts, and its held vertices opened with their wedges and the
  // joins the block made between them.
  void add_block(const SinkBlock& b, std::uint32_t first_vertex, std::uint32_t first_group,
                 const BlockCount& block) {
    if (first_vertex != numbered) complete = false;
    numbered += static_cast<std::uint32_t>(b.ids.size());
    stats.triangles += block.triangles;
    stats.degenerate_triangles += block.degenerate;
    stats.duplicate_triangles += block.duplicates;
    counts += block.counts;
    for (const auto& [pair, ways] : block.pairs) {
      const std::uint64_t g1 = (pair >> 32) + first_group, g2 = (pair & 0xFFFFFFFFu) + first_group;
      std::array<std::uint64_t, 2>& total = group_pairs[g1 << 32 | g2];
      total[0] += ways[0];
      total[1] += ways[1];
    }
    std::vector<std::uint32_t> opened(block.held.size());
    for (std::size_t h = 0; h < block.held.size(); ++h) {
      const std::uint32_t v = block.held[h];
      opened[h] = add_held(first_vertex + v, &b.xyz[3 * std::size_t{v}]);
      Open& record = open(opened[h]);
      for (std::uint32_t w = block.held_start[h]; w < block.held_start[h + 1]; ++w) {
        const Wedge& wedge = block.held_wedges[w];
        add_wedge(record, {first_vertex + wedge.next, first_vertex + wedge.prev,
                           first_group + wedge.group});
      }
    }
    components.merges += block.component_merges;
    for (const auto& [a, c] : block.component_links) {
      components.unite(node[opened[a]].component, node[opened[c]].component);
    }
    boundary_merges += block.boundary_merges;
    for (const auto& [a, c] : block.boundary_links) {
      const std::uint64_t before = borders.merges;
      borders.unite(node[opened[a]].border, node[opened[c]].border);
      boundary_merges += borders.merges - before;
    }
    if (components.parent.size() > 2 * open_count + 4096) compact();
  }

  // Rebuilds both forests over the roots the open vertices reach (after noting the peak: the
  // forests shrink here, the rest never does).
  void compact() {
    peak = std::max(peak, bytes());
    std::vector<std::uint32_t*> component_nodes, border_nodes;
    for (Nodes& v : node) {
      if (v.refs == 0) continue;  // a free slot
      component_nodes.push_back(&v.component);
      border_nodes.push_back(&v.border);
    }
    components.compact(component_nodes);
    borders.compact(border_nodes);
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
    const Open& v = open(first);
    return holds_triangle({v.inline_wedges, std::min(v.wedges, kInlineWedges)}, rep[1], rep[2]) ||
           (v.overflow != kNoIndex && holds_triangle(overflow[v.overflow], rep[1], rep[2]));
  }

  void add_triangle(const Triangle& numbers, const std::array<const double*, 3>& xyz,
                    std::uint32_t group) {
    ++stats.triangles;
    std::array<std::uint32_t, 3> o{};
    for (int k = 0; k < 3; ++k) {
      o[k] = open_of.find(numbers[k]);
      if (o[k] == NumberMap::kMissing) {
        complete = false;  // a corner already done: the counts can no longer be exact
        return;
      }
    }
    double p[3][3];
    for (int k = 0; k < 3; ++k) stored_position(xyz[k], float_positions, p[k]);
    if (degenerate(o, p)) {
      ++stats.degenerate_triangles;
      return;
    }
    if (edges_summed < kEdgesForCells) {
      for (int k = 0; k < 3; ++k) {
        edge_sum += std::abs(p[1][k] - p[0][k]);
      }
      if (++edges_summed == kEdgesForCells) size_cells();
    }
    const Triangle rep{open(o[0]).rep, open(o[1]).rep, open(o[2]).rep};
    if (duplicate(rep, o[0])) {
      ++stats.duplicate_triangles;
      return;
    }
    for (int k = 0; k < 3; ++k) add_wedge(open(o[k]), {rep[(k + 1) % 3], rep[(k + 2) % 3], group});
    components.unite(node[o[0]].component, node[o[1]].component);
    components.unite(node[o[0]].component, node[o[2]].component);
  }

  void done(std::uint32_t number) {
    const std::uint32_t o = open_of.find(number);
    if (o == NumberMap::kMissing) return;
    if (number != open(o).rep) open_of.erase(number);
    if (--node[o].refs == 0) judge(o);
  }

  // v's star is complete: count its fans and its edges, then forget it. Every edge is seen from
  // both ends with the same triangles, so edge counts are taken at both ends and halved at the
  // end; only a boundary edge looks up its other end, to join the two in the boundary graph
  // while both are open.
  void judge(std::uint32_t o) {
    Open& vertex = open(o);
    std::span<const Wedge> wedges(vertex.inline_wedges, std::min(vertex.wedges, kInlineWedges));
    if (vertex.overflow != kNoIndex) {
      star.assign(wedges.begin(), wedges.end());
      star.insert(star.end(), overflow[vertex.overflow].begin(), overflow[vertex.overflow].end());
      wedges = star;
      overflow[vertex.overflow].clear();
      free_overflow.push_back(vertex.overflow);
    }
    star_judge.judge(
        wedges, counts, [&](std::uint32_t w) { join_boundary(o, w); },
        [&](std::uint32_t g1, std::uint32_t g2, bool opposite) {
          ++group_pairs[std::uint64_t{g1} << 32 | g2][opposite ? 1 : 0];
        });
    open_of.erase(vertex.rep);
    if (welding) welder_erase(o);
    node[o].refs = 0;
    free_open.push_back(o);
    --open_count;
  }

  // Joins v and the other end w of a boundary edge in the boundary graph, if w is still open
  // (else they were joined when w was judged).
  void join_boundary(std::uint32_t o, std::uint32_t w_number) {
    const std::uint32_t w = open_of.find(w_number);
    if (w == NumberMap::kMissing) return;
    const std::uint64_t before = borders.merges;
    borders.unite(node[o].border, node[w].border);
    boundary_merges += borders.merges - before;
  }

  void finish(std::span<const std::uint8_t> flip) {
    for (std::uint32_t o = 0; o < slots; ++o) {
      if (node[o].refs > 0) {
        node[o].refs = 1;
        judge(o);
      }
    }
    for (const auto& [pair, ways] : group_pairs) {
      const auto g1 = static_cast<std::uint32_t>(pair >> 32), g2 = static_cast<std::uint32_t>(pair);
      const bool one_flipped = (g1 < flip.size() && flip[g1]) != (g2 < flip.size() && flip[g2]);
      counts.conflict_ends += one_flipped ? ways[1] : ways[0];
    }
    stats.vertices = counts.vertices;
    stats.non_manifold_vertices = counts.non_manifold_vertices;
    stats.non_manifold_vertices_type1 = counts.non_manifold_vertices_type1;
    stats.non_manifold_vertices_type2 = counts.non_manifold_vertices_type2;
    stats.boundary_edges = counts.boundary_ends / 2;
    stats.orientation_conflicts = counts.conflict_ends / 2;
    stats.non_manifold_edges = counts.non_manifold_ends / 2;
    stats.holes = stats.boundary_edges - boundary_merges;
    stats.components = stats.vertices - components.merges;
  }

  std::uint64_t bytes() const {
    std::uint64_t overflowing = 0;
    for (const std::vector<Wedge>& list : overflow) overflowing += list.capacity() * sizeof(Wedge);
    return chunks.size() * (sizeof(Open) << kChunkBits) + node.capacity() * sizeof(Nodes) +
           position.capacity() * sizeof(position[0]) + overflowing +
           (2 * welder.capacity() + free_open.capacity() + components.parent.capacity() +
            borders.parent.capacity()) *
               sizeof(std::uint32_t) +
           open_of.bytes() + group_pairs.size() * 48;
  }
};

StreamStats::StreamStats(MeshSink& next, bool float_positions, bool positions_distinct)
    : impl_(std::make_unique<Impl>(next, float_positions, positions_distinct)) {}
StreamStats::~StreamStats() = default;

// The next sink first: it reads the position anyway (the writer stores it), so the counter finds
// it in cache and a profile charges the counter only for its own work.
void StreamStats::vertex(Index id, const double xyz[3]) {
  impl_->next.vertex(id, xyz);
  impl_->add_vertex(xyz);
}

void StreamStats::triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                           std::uint32_t group) {
  impl_->add_triangle(corners, xyz, group);
  impl_->next.triangle(corners, xyz, group);
}

void StreamStats::vertex_done(std::uint32_t vertex) {
  impl_->done(vertex);
  impl_->next.vertex_done(vertex);
}

std::unique_ptr<SinkBlockWork> StreamStats::prepare(const SinkBlock& block) const {
  // Welding needs the positions of every open vertex: such blocks go triangle by triangle.
  if (impl_->welding) return nullptr;
  std::unique_ptr<BlockCount> work = count_block(block, impl_->float_positions);
  work->next = impl_->next.prepare(block);
  return work;
}

void StreamStats::block(const SinkBlock& block, std::uint32_t first_vertex,
                        std::uint32_t first_group, std::unique_ptr<SinkBlockWork> work) {
  if (!work) {
    MeshSink::block(block, first_vertex, first_group, nullptr);
    return;
  }
  // Only prepare() makes this sink's work.
  auto& counted = static_cast<BlockCount&>(*work);
  impl_->add_block(block, first_vertex, first_group, counted);
  impl_->next.block(block, first_vertex, first_group, std::move(counted.next));
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
  return std::max(impl_->peak, impl_->bytes());
}

}  // namespace g2s
