// Mesh defect measurement (docs/algorithm.md §9, "Measuring a mesh"): welds vertices by exact
// position, sets degenerate and duplicate triangles aside, then walks every vertex's star once to
// count edges, fans and holes. Linear time and lean memory: open-addressing hash tables on flat
// arrays, a CSR vertex->triangle table and union-find, no sorting and no std::unordered_map.
#include "g2s/stats.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <new>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "common/exact_predicates.hpp"
#include "common/mix64.hpp"
#include "g2s/error.hpp"
#include "stats/point_distances.hpp"
#include "stats/self_intersections.hpp"

namespace g2s {
namespace {

// A hint to start loading `p` into cache: the hash-table probes here are random accesses into
// tables far larger than the cache, so each loop asks a few iterations ahead.
inline void prefetch(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(p);
#else
  (void)p;
#endif
}

// Allocator for the big flat tables: blocks of 8 MB and more are aligned to 2 MB and marked for
// transparent huge pages on Linux, which cuts page faults and TLB misses on random probes (a
// large share of the time in virtual machines). Elsewhere it is plain operator new.
template <typename T>
struct BigAllocator {
  using value_type = T;
  BigAllocator() = default;
  template <typename U>
  BigAllocator(const BigAllocator<U>&) noexcept {}  // NOLINT(google-explicit-constructor)

  static constexpr std::size_t kHuge = std::size_t{2} << 20;
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
#if defined(__linux__)
    if (bytes >= 4 * kHuge) {
      const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
      void* p = std::aligned_alloc(kHuge, rounded);
      if (p == nullptr) throw std::bad_alloc();
      madvise(p, rounded, MADV_HUGEPAGE);
      return static_cast<T*>(p);
    }
#endif
    return static_cast<T*>(::operator new (bytes, std::align_val_t{alignof(T)}));
  }
  void deallocate(T* p, std::size_t n) noexcept {
#if defined(__linux__)
    if (n * sizeof(T) >= 4 * kHuge) {
      std::free(p);
      return;
    }
#endif
    ::operator delete (p, std::align_val_t{alignof(T)});
  }
  template <typename U>
  bool operator==(const BigAllocator<U>&) const noexcept {
    return true;
  }
};

template <typename T>
using Table = std::vector<T, BigAllocator<T>>;

// A power of two with room for n keys at a load factor of at most 2/3.
std::size_t table_capacity(std::size_t n) {
  std::size_t capacity = 16;
  while (capacity < n + n / 2) capacity <<= 1;
  return capacity;
}

// Bit patterns with -0.0 folded onto +0.0, so that exact equality of the numbers is equality of
// the patterns (NaNs are equal when their patterns are).
std::uint64_t key_bits(double d) {
  return std::bit_cast<std::uint64_t>(d == 0.0 ? 0.0 : d);
}
std::uint32_t key_bits(float f) {
  return std::bit_cast<std::uint32_t>(f == 0.0f ? 0.0f : f);
}

std::uint64_t position_hash(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  return mix64(x * 0x9e3779b97f4a7c15ULL ^ mix64(y + 0x632be59bd9b4e019ULL) ^ (z << 1 | z >> 63));
}

// Union-find over 32-bit ids with path halving; unite() says whether two sets were merged.
template <typename Parents>
Index find_root(Parents& parent, Index x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

template <typename Parents>
bool unite(Parents& parent, Index a, Index b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a == b) return false;
  if (a < b) std::swap(a, b);
  parent[a] = b;
  return true;
}

// The mesh's non-degenerate triangles over welded vertex ids 0..rep.size()-1, in input order;
// rep[w] is the first input vertex that has welded vertex w's position.
struct Welded {
  Table<Triangle> triangles;
  Table<Index> rep;
};

// Two equal welded corners, or three exactly collinear corners. A triangle with a NaN or infinite
// coordinate is not degenerate (it has no defined shape); the crossing test leaves it out.
bool is_degenerate(const Triangle& t, const Triangle& input, const double* xyz) {
  if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
  const double* corner[3];
  for (int k = 0; k < 3; ++k) {
    corner[k] = xyz + 3 * std::size_t{input[k]};
    for (int d = 0; d < 3; ++d) {
      if (!std::isfinite(corner[k][d])) return false;
    }
  }
  return exact::collinear(corner[0], corner[1], corner[2]);
}

// Welds the corners by exact position and drops (and counts) degenerate triangles. The position
// table holds (32 hash bits << 32 | welded id) so that probing rarely touches the coordinates;
// it is sized for min(input vertices, triangles) and doubles if more positions turn up.
Welded weld(const IndexedMesh& mesh, MeshStats& stats) {
  const std::size_t n = mesh.vertex_count();
  const std::size_t count = mesh.triangles.size();
  if (count >= std::numeric_limits<Index>::max()) {
    throw Error(Exit::bad_input, "mesh has " + std::to_string(count) +
                                     " triangles; stats handles at most 4,294,967,294");
  }
  constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  Welded out;
  out.triangles.reserve(count);
  Table<Index> remap(n, kNoIndex);  // input vertex -> welded id
  // Room for n positions, or for one per triangle in a soup (about half that many are distinct).
  Table<std::uint64_t> table(table_capacity(std::min(n, count)), kEmpty);
  std::size_t mask = table.size() - 1;
  const double* xyz = mesh.xyz.data();
  auto grow = [&] {
    Table<std::uint64_t> bigger(2 * table.size(), kEmpty);
    mask = bigger.size() - 1;
    for (const std::uint64_t e : table) {
      if (e == kEmpty) continue;
      std::size_t s = (e >> 32) & mask;
      while (bigger[s] != kEmpty) s = (s + 1) & mask;
      bigger[s] = e;
    }
    table.swap(bigger);
  };
  auto hash_of = [xyz](Index i) {
    return position_hash(key_bits(xyz[3 * std::size_t{i}]), key_bits(xyz[3 * std::size_t{i} + 1]),
                         key_bits(xyz[3 * std::size_t{i} + 2])) >>
           32;
  };
  constexpr std::size_t kAhead = 32;  // triangles: the corners' positions, then their slots
  for (std::size_t t = 0; t < count; ++t) {
    if (t + kAhead < count) {
      for (const Index i : mesh.triangles[t + kAhead]) {
        if (i < n) {
          prefetch(&remap[i]);
          prefetch(xyz + 3 * std::size_t{i});
        }
      }
    }
    if (t + kAhead / 2 < count) {
      for (const Index i : mesh.triangles[t + kAhead / 2]) {
        if (i < n && remap[i] == kNoIndex) prefetch(&table[hash_of(i) & mask]);
      }
    }
    const Triangle& input = mesh.triangles[t];
    Triangle welded{};
    for (int c = 0; c < 3; ++c) {
      const Index i = input[c];
      if (i >= n) {
        throw Error(Exit::bad_input, "triangle " + std::to_string(t) + " uses vertex " +
                                         std::to_string(i) + " but the mesh has " +
                                         std::to_string(n) + " vertices");
      }
      if (remap[i] == kNoIndex) {
        const std::uint64_t x = key_bits(xyz[3 * std::size_t{i}]);
        const std::uint64_t y = key_bits(xyz[3 * std::size_t{i} + 1]);
        const std::uint64_t z = key_bits(xyz[3 * std::size_t{i} + 2]);
        const std::uint64_t hash = hash_of(i);
        for (std::size_t s = hash & mask;; s = (s + 1) & mask) {
          const std::uint64_t e = table[s];
          if (e == kEmpty) {
            const auto id = static_cast<Index>(out.rep.size());
            table[s] = hash << 32 | id;
            out.rep.push_back(i);
            remap[i] = id;
            if (3 * out.rep.size() > 2 * table.size()) grow();
            break;
          }
          if (e >> 32 != hash) continue;
          const auto w = static_cast<Index>(e);
          const double* p = xyz + 3 * std::size_t{out.rep[w]};
          if (key_bits(p[0]) == x && key_bits(p[1]) == y && key_bits(p[2]) == z) {
            remap[i] = w;
            break;
          }
        }
      }
      welded[c] = remap[i];
    }
    if (is_degenerate(welded, input, xyz)) {
      ++stats.degenerate_triangles;
    } else {
      out.triangles.push_back(welded);
    }
  }
  out.triangles.shrink_to_fit();
  return out;
}

// One edge {v, w} as seen from v while walking v's star.
struct EdgeGroup {
  Index w;              // the other end
  std::uint32_t count;  // triangles of the star on this edge
  std::uint32_t first;  // the first two of them (positions in the star)
  std::uint32_t second;
  std::uint32_t out;  // how many traverse it v -> w
};

// A set of the used vertices' positions, for coverage: rounded to float (STL's precision) when
// kFloat, else exact.
template <bool kFloat>
class PositionSet {
 public:
  explicit PositionSet(std::size_t count) : keys_(table_capacity(count), kEmpty) {}

  // Starts loading the slot where p's key would be looked up first.
  void prepare(const double* p) const {
    const Key key = make_key(p);
    prefetch(&keys_[position_hash(key.x, key.y, key.z) & (keys_.size() - 1)]);
  }
  void insert(const double* p) {
    const Key key = make_key(p);
    if (key == kEmpty) {
      has_empty_key_ = true;
      return;
    }
    Key& slot = keys_[find(key)];
    slot = key;
  }
  bool contains(const double* p) const {
    const Key key = make_key(p);
    return key == kEmpty ? has_empty_key_ : keys_[find(key)] == key;
  }

 private:
  using Bits = std::conditional_t<kFloat, std::uint32_t, std::uint64_t>;
  struct Key {
    Bits x, y, z;
    // Member by member: std::array's == becomes a memcmp call in this hot loop.
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  static constexpr Key kEmpty = {~Bits{0}, ~Bits{0}, ~Bits{0}};  // a NaN pattern

  static Key make_key(const double* p) {
    if constexpr (kFloat) {
      return {key_bits(static_cast<float>(p[0])), key_bits(static_cast<float>(p[1])),
              key_bits(static_cast<float>(p[2]))};
    } else {
      return {key_bits(p[0]), key_bits(p[1]), key_bits(p[2])};
    }
  }
  // The slot holding `key`, or the empty slot where it would go.
  std::size_t find(const Key& key) const {
    const std::size_t mask = keys_.size() - 1;
    std::size_t s = position_hash(key.x, key.y, key.z) & mask;
    while (keys_[s] != key && keys_[s] != kEmpty) s = (s + 1) & mask;
    return s;
  }

  Table<Key> keys_;
  bool has_empty_key_ = false;
};

// Counts in stats the input points whose position a used vertex has (vertex(w): welded vertex
// w's coordinates, used(w): whether a kept triangle uses it); the others go to off_mesh.
template <bool kFloat, class Vertex, class Used>
void cover(std::size_t vertex_count, Vertex&& vertex, Used&& used, const PointCloud& input_points,
           MeshStats& stats, Table<std::uint64_t>& off_mesh) {
  PositionSet<kFloat> positions(stats.vertices);
  constexpr std::size_t kAhead = 16;
  for (std::size_t w = 0; w < vertex_count; ++w) {
    if (w + kAhead < vertex_count) positions.prepare(vertex(w + kAhead));
    if (used(w)) positions.insert(vertex(w));
  }
  const std::size_t points = input_points.size();
  const double* point = input_points.xyz.data();
  for (std::size_t i = 0; i < points; ++i) {
    if (i + kAhead < points) positions.prepare(point + 3 * (i + kAhead));
    if (positions.contains(point + 3 * i)) {
      ++stats.covered_points;
    } else {
      off_mesh.push_back(i);
    }
  }
}

// Everything that needs a vertex's star: duplicates, edge classes, fans, and the boundary
// graph's cycles. Offset is the CSR offset type (32-bit when the table is small enough).
template <typename Offset>
void measure_stars(Table<Triangle>& triangles, std::size_t vertex_count, const Table<Index>& rep,
                   const IndexedMesh& mesh, const PointCloud* input_points, MeshStats& stats,
                   Table<std::uint64_t>& off_mesh) {
  // CSR vertex -> triangles, each star in input order.
  Table<Offset> offset(vertex_count + 1, 0);
  for (const Triangle& t : triangles) {
    ++offset[t[0] + 1];
    ++offset[t[1] + 1];
    ++offset[t[2] + 1];
  }
  for (std::size_t v = 0; v < vertex_count; ++v) {
    if (offset[v + 1] != 0) ++stats.vertices;
    offset[v + 1] += offset[v];
  }
  Table<Index> star(static_cast<std::size_t>(offset[vertex_count]));
  {
    Table<Offset> fill(offset.begin(), offset.end() - 1);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      for (const Index v : triangles[t]) star[fill[v]++] = static_cast<Index>(t);
    }
  }

  // Components: union the corners of every triangle (duplicates change nothing here).
  Table<Index> parent(vertex_count);
  std::iota(parent.begin(), parent.end(), Index{0});
  std::uint64_t merges = 0;
  for (const Triangle& t : triangles) {
    merges += unite(parent, t[0], t[1]) ? 1 : 0;
    merges += unite(parent, t[0], t[2]) ? 1 : 0;
  }
  stats.components = stats.vertices - merges;

  // The same array again for the boundary-edge graph: its cycle rank E - V + C is the number of
  // boundary edges that joined two vertices already connected.
  std::iota(parent.begin(), parent.end(), Index{0});
  std::uint64_t boundary_merges = 0;

  // Per-star scratch. slot[w] is w's group in the current star when groups[slot[w]].w == w
  // (a sparse set: nothing to clear between stars).
  Table<std::uint32_t> slot(vertex_count, 0);
  std::vector<EdgeGroup> groups;
  std::vector<std::uint32_t> group_next, group_prev, fan;
  std::vector<unsigned char> open;
  std::vector<std::uint64_t> seen;  // duplicate check: (middle << 32 | largest) corners
  constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  constexpr Triangle kDuplicate = {kNoIndex, kNoIndex, kNoIndex};
  constexpr std::size_t kStarsAhead = 4;

  for (std::size_t vv = 0; vv < vertex_count; ++vv) {
    const auto v = static_cast<Index>(vv);
    const Offset begin = offset[v];
    const auto size = static_cast<std::size_t>(offset[v + 1] - begin);
    // A few stars ahead, the triangles; half as far, their corners' slots.
    if (vv + kStarsAhead < vertex_count) {
      for (Offset j = offset[vv + kStarsAhead]; j < offset[vv + kStarsAhead + 1]; ++j) {
        prefetch(&triangles[star[j]]);
      }
    }
    if (vv + kStarsAhead / 2 < vertex_count) {
      for (Offset j = offset[vv + kStarsAhead / 2]; j < offset[vv + kStarsAhead / 2 + 1]; ++j) {
        for (const Index w : triangles[star[j]]) {
          if (w != kNoIndex) prefetch(&slot[w]);
        }
      }
    }
    if (size == 0) continue;

    // Duplicates are found at their smallest corner, which is visited before the other two:
    // a later copy of a kept triangle's vertex set is marked kDuplicate and skipped from then on.
    std::size_t capacity = 8;
    while (capacity < 2 * size) capacity <<= 1;
    seen.assign(capacity, kEmpty);
    for (std::size_t i = 0; i < size; ++i) {
      Triangle& t = triangles[star[begin + i]];
      if (t[0] == kNoIndex || std::min({t[0], t[1], t[2]}) != v) continue;
      const Index hi = std::max({t[0], t[1], t[2]});
      const Index mid = t[0] ^ t[1] ^ t[2] ^ v ^ hi;
      const std::uint64_t key = std::uint64_t{mid} << 32 | hi;
      std::size_t s = mix64(key) & (capacity - 1);
      while (seen[s] != kEmpty && seen[s] != key) s = (s + 1) & (capacity - 1);
      if (seen[s] == key) {
        ++stats.duplicate_triangles;
        t = kDuplicate;
      } else {
        seen[s] = key;
      }
    }

    // Group the star's triangles by their edges at v.
    groups.clear();
    group_next.clear();
    group_prev.clear();
    auto touch = [&](Index w, std::uint32_t i, std::uint32_t outgoing) {
      std::uint32_t g = slot[w];
      if (g >= groups.size() || groups[g].w != w) {
        g = static_cast<std::uint32_t>(groups.size());
        slot[w] = g;
        groups.push_back({w, 0, i, 0, 0});
      }
      EdgeGroup& group = groups[g];
      if (group.count == 1) group.second = i;
      ++group.count;
      group.out += outgoing;
      return g;
    };
    for (std::size_t j = 0; j < size; ++j) {
      const Triangle& t = triangles[star[begin + j]];
      if (t[0] == kNoIndex) continue;  // a duplicate
      const int p = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
      const auto i = static_cast<std::uint32_t>(group_next.size());
      group_next.push_back(touch(t[(p + 1) % 3], i, 1));  // the triangle runs v -> next
      group_prev.push_back(touch(t[(p + 2) % 3], i, 0));  // and prev -> v
    }
    const std::size_t k = group_next.size();

    // Fans: star triangles joined across the edges at v that have exactly two triangles.
    fan.resize(k);
    std::iota(fan.begin(), fan.end(), std::uint32_t{0});
    for (const EdgeGroup& g : groups) {
      if (g.count == 2) unite(fan, g.first, g.second);
      if (v < g.w) {  // each edge once, from its lower end
        if (g.count == 1) {
          ++stats.boundary_edges;
          boundary_merges += unite(parent, v, g.w) ? 1 : 0;
        } else if (g.count == 2) {
          if (g.out != 1) ++stats.orientation_conflicts;
        } else {
          ++stats.non_manifold_edges;
        }
      }
    }
    // A fan is closed when each of its triangles has both edges at v shared within the fan.
    open.assign(k, 0);
    std::size_t fans = 0;
    for (std::size_t i = 0; i < k; ++i) {
      const auto ii = static_cast<std::uint32_t>(i);
      const std::uint32_t root = find_root(fan, ii);
      if (root == ii) ++fans;
      if (groups[group_next[i]].count != 2 || groups[group_prev[i]].count != 2) open[root] = 1;
    }
    if (fans > 1) {
      ++stats.non_manifold_vertices;
      bool any_closed = false;
      for (std::size_t i = 0; i < k; ++i) {
        if (fan[i] == i && open[i] == 0) any_closed = true;
      }
      ++(any_closed ? stats.non_manifold_vertices_type1 : stats.non_manifold_vertices_type2);
    }
  }
  stats.holes = stats.boundary_edges - boundary_merges;

  if (input_points == nullptr) return;
  // Coverage, with the big tables of the star pass released first.
  Table<Index>().swap(parent);
  Table<std::uint32_t>().swap(slot);
  Table<Index>().swap(star);
  auto vertex = [&](std::size_t w) { return mesh.xyz.data() + 3 * std::size_t{rep[w]}; };
  auto used = [&](std::size_t w) { return offset[w + 1] != offset[w]; };
  // At float precision (STL's) when every used vertex lies on floats, as an STL's all do, so that
  // an STL of a double cloud covers it; else exactly, as a double mesh holds the points: at
  // georeferenced coordinates float's step is half a metre, and points that far apart would count
  // as one.
  bool floats = true;
  for (std::size_t w = 0; w < vertex_count && floats; ++w) {
    if (!used(w)) continue;
    for (int k = 0; k < 3; ++k) {
      floats = floats && static_cast<double>(static_cast<float>(vertex(w)[k])) == vertex(w)[k];
    }
  }
  const std::size_t points = input_points->size();
  stats.has_coverage = true;
  stats.input_points = points;
  if (floats) {
    cover<true>(vertex_count, vertex, used, *input_points, stats, off_mesh);
  } else {
    cover<false>(vertex_count, vertex, used, *input_points, stats, off_mesh);
  }
  stats.coverage =
      points == 0 ? 0.0 : static_cast<double>(stats.covered_points) / static_cast<double>(points);
}

// The exact predicates behind the crossing count hold while products of coordinate differences
// stay in double's normal range: coordinates of extreme magnitude (an axis whose largest is
// below 2^-100, such as subnormal ones, or above 2^100) make them underflow or overflow and
// answer wrongly. Scaling an axis by a power of two is exact and changes the sign of no
// orientation or the answer of no comparison, so such axes are scaled to a largest magnitude in
// [0.5, 1), in a copy. Empty when no axis needs it (every real scan).
std::vector<double> scaled_for_predicates(std::span<const double> xyz) {
  double largest[3] = {0, 0, 0};
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    if (std::isfinite(xyz[i])) largest[i % 3] = std::max(largest[i % 3], std::abs(xyz[i]));
  }
  int shift[3] = {0, 0, 0};
  bool any = false;
  for (int a = 0; a < 3; ++a) {
    if (largest[a] == 0 || (largest[a] >= 0x1p-100 && largest[a] <= 0x1p100)) continue;
    std::frexp(largest[a], &shift[a]);
    shift[a] = -shift[a];
    any = true;
  }
  if (!any) return {};
  std::vector<double> scaled(xyz.begin(), xyz.end());
  for (std::size_t i = 0; i < scaled.size(); ++i) scaled[i] = std::ldexp(scaled[i], shift[i % 3]);
  return scaled;
}

}  // namespace

MeshStats compute_stats(const IndexedMesh& mesh, const PointCloud* input_points) {
  MeshStats stats;
  stats.triangles = mesh.triangles.size();
  Welded welded = weld(mesh, stats);
  Table<std::uint64_t> off_mesh;  // input points that are not vertices
  const std::size_t vertex_count = welded.rep.size();
  if (3 * welded.triangles.size() < std::numeric_limits<std::uint32_t>::max()) {
    measure_stars<std::uint32_t>(welded.triangles, vertex_count, welded.rep, mesh, input_points,
                                 stats, off_mesh);
  } else {
    measure_stars<std::uint64_t>(welded.triangles, vertex_count, welded.rep, mesh, input_points,
                                 stats, off_mesh);
  }
  const std::vector<double> scaled = scaled_for_predicates(mesh.xyz);
  const stats::CrossingCounts crossings = stats::count_crossings(
      welded.triangles, scaled.empty() ? mesh.xyz.data() : scaled.data(), welded.rep);
  stats.crossing_pairs = crossings.pairs;
  stats.crossing_pairs_no_shared_vertex = crossings.pairs_no_shared_vertex;
  stats.crossing_triangles = crossings.triangles;
  if (input_points != nullptr) {
    stats::measure_point_distances(welded.triangles, mesh.xyz.data(), welded.rep, *input_points,
                                   off_mesh, stats);
  }
  return stats;
}

}  // namespace g2s
