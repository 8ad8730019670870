// Flat hash grid for fixed-radius neighbour search (docs/algorithm.md §1). Points are sorted once
// into Morton order of their cells (a radix sort), so a cell's points are contiguous and
// neighbouring cells lie close in memory; non-empty cells are found through an open-addressing
// hash of their 4x4x4 blocks' Morton codes, so empty space costs nothing. Exact duplicate points
// are merged while sorting (the one with the smallest id is kept).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <span>
#include <vector>

#include "common/vec3.hpp"
#include "g2s/types.hpp"

namespace g2s {

class HashGrid {
 public:
  // Builds the grid over xyz (3 floats per point) with global ids (empty: 0..n-1). The cell
  // edge is chosen from the estimated sampling spacing. With group_distance > 0 (points in
  // groups, TileSource::group_distance), the spacing is measured beyond it. With twin_distance >
  // 0 (a cloud of twins, TileSource::twin_distance), a point with a smaller id within that
  // distance is left out as a near-copy, unless keep (empty, or one flag per point of xyz) flags
  // it.
  HashGrid(std::span<const float> xyz, std::span<const Index> ids, double group_distance = 0,
           double twin_distance = 0, std::span<const std::uint8_t> keep = {});

  std::uint32_t size() const { return static_cast<std::uint32_t>(points_.size()); }
  const Vec3f& point(std::uint32_t i) const { return points_[i]; }
  Vec3 position(std::uint32_t i) const { return Vec3(points_[i]); }
  Index id(std::uint32_t i) const { return ids_[i]; }
  // The point's index in the xyz the grid was built from.
  std::uint32_t source(std::uint32_t i) const { return sources_[i]; }
  std::span<const Vec3f> points() const { return points_; }
  std::uint64_t duplicates_merged() const { return duplicates_; }
  std::uint64_t twins_left_out() const { return twins_; }  // near-copies left out
  // The median nearest-neighbour distance of a sample (beyond the group distance, if any).
  double spacing() const { return spacing_; }
  // A lower 95% confidence bound of that median: the sample's order statistic of rank
  // m/2 - 1.96 sqrt(m)/2 (m distances), above the true median with probability about 2.5%
  // whatever their distribution (the count below the median is binomial). 0 where spacing() is.
  double spacing_lower_bound() const { return spacing_lower_bound_; }
  double cell_size() const { return cell_; }

  // A ball query as for_each_in_ball answers it: the test and the cells it scans.
  class BallQuery {
   public:
    BallQuery(const HashGrid& grid, const Vec3& centre, double radius);
    // Exactly whether the query visits point i (and with which squared distance).
    bool visits(const HashGrid& grid, std::uint32_t i) const;

   private:
    friend class HashGrid;
    static double d2_of(const Vec3f& p, const Vec3& centre) {
      const double dx = p.x - centre.x, dy = p.y - centre.y, dz = p.z - centre.z;
      return dx * dx + dy * dy + dz * dz;
    }
    Vec3 centre_;
    double r2_;
    std::int64_t lo_[3], hi_[3];  // the cells' box
    bool scan_all_;  // a ball spanning more cells than there are points: scan the points
  };

  // Calls visit(i, squared distance) for every point within radius of centre.
  template <class Visit>
  void for_each_in_ball(const Vec3& centre, double radius, Visit&& visit) const {
    for_each_in_ball(BallQuery(*this, centre, radius), visit);
  }
  template <class Visit>
  void for_each_in_ball(const BallQuery& query, Visit&& visit) const;

  // Nearest point to point i among those accepted by keep(j), within max_radius; kNoIndex if
  // none.
  template <class Keep>
  std::uint32_t nearest(std::uint32_t i, double max_radius, Keep&& keep) const;

 private:
  void build(std::span<const float> xyz, std::span<const Index> ids, double cell);
  // Sets spacing_ and spacing_lower_bound_.
  void estimate_spacing();
  std::int64_t cell_coord(double v, int axis) const {
    return static_cast<std::int64_t>(std::floor((v - origin_[axis]) * inv_cell_));
  }
  // cell_coord clamped to the grid; clamped first, so that a cast rounds the same as floor (no
  // call to floor).
  std::int64_t clamped_coord(double v, int axis) const {
    const double c = (v - origin_[axis]) * inv_cell_;
    return static_cast<std::int64_t>(
        std::min(std::max(c, 0.0), static_cast<double>(dims_[axis] - 1)));
  }
  // A 4x4x4 block of cells (the low 6 Morton bits of a cell) that holds points: which of its 64
  // cells do, and where its first non-empty cell is in cell_begin_ (the block's cells follow in
  // Morton order). One probe finds all 64 cells and an empty cell costs no memory access: a
  // front query (2-3 cells per axis) touches a few blocks instead of probing every cell.
  struct alignas(32) Block {
    std::uint64_t code;   // the cells' Morton code >> 6
    std::uint64_t cells;  // bit k: the cell with low Morton bits k holds points
    std::uint32_t first;
  };
  std::uint64_t slot_of(std::uint64_t block) const {
    return (block * 0x9E3779B97F4A7C15ull) >> slot_shift_;  // the top bits are the best mixed
  }
  const Block* find_block(std::uint64_t block) const;

  std::vector<Vec3f> points_;
  std::vector<Index> ids_;
  std::vector<std::uint32_t> sources_;
  std::vector<std::uint32_t>
      cell_begin_;             // non-empty cells in Morton order, + 1: offsets into points_
  std::vector<Block> blocks_;  // open addressing, linear probing, load <= 1/2
  std::uint64_t slot_mask_ = 0;
  int slot_shift_ = 64;           // 64 - log2(blocks_.size())
  double origin_[3] = {0, 0, 0};  // bounding box: lowest corner
  double extent_[3] = {0, 0, 0};  // and size
  double cell_ = 1.0;
  double inv_cell_ = 1.0;
  std::int64_t dims_[3] = {1, 1, 1};
  double spacing_ = 0.0;
  double spacing_lower_bound_ = 0.0;
  std::uint64_t duplicates_ = 0;
  std::uint64_t twins_ = 0;
  double group_distance_ = 0;
};

// std::popcount without a library call on targets built without a popcount instruction (the
// default x86-64 build calls libgcc for it, a measurable cost in ball queries).
inline std::size_t bit_count(std::uint64_t v) {
  v -= v >> 1 & 0x5555555555555555ull;
  v = (v & 0x3333333333333333ull) + (v >> 2 & 0x3333333333333333ull);
  v = (v + (v >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<std::size_t>(v * 0x0101010101010101ull >> 56);
}

// Interleaves the low 21 bits of x, y, z.
inline std::uint64_t morton3(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  auto spread = [](std::uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
  };
  return spread(x) | spread(y) << 1 | spread(z) << 2;
}

inline const HashGrid::Block* HashGrid::find_block(std::uint64_t block) const {
  for (std::uint64_t slot = slot_of(block);; slot = (slot + 1) & slot_mask_) {
    const Block& b = blocks_[slot];
    if (b.code == block) return &b;
    if (b.code == ~0ull) return nullptr;
  }
}

// The cells of a 4x4x4 block whose coordinate along `axis` lies in [lo, hi] (0..3), as a mask
// over the block's 64 cells in Morton order (bit k: low Morton bits k).
constexpr std::uint64_t block_slab(int axis, int lo, int hi) {
  std::uint64_t mask = 0;
  for (int k = 0; k < 64; ++k) {
    const int v = (k >> axis & 1) | (k >> (axis + 3) & 1) << 1;
    if (v >= lo && v <= hi) mask |= std::uint64_t{1} << k;
  }
  return mask;
}

inline HashGrid::BallQuery::BallQuery(const HashGrid& grid, const Vec3& centre, double radius)
    : centre_(centre), r2_(radius * radius) {
  const double c[3] = {centre.x, centre.y, centre.z};
  // A ball spanning more cells than there are points (far outliers, very uneven density) is
  // cheaper to answer by scanning the points than by probing mostly empty cells.
  double box_cells = 1;
  for (int a = 0; a < 3; ++a) {
    lo_[a] = grid.clamped_coord(c[a] - radius, a);
    hi_[a] = grid.clamped_coord(c[a] + radius, a);
    box_cells *= static_cast<double>(hi_[a] - lo_[a] + 1);
  }
  scan_all_ = box_cells > static_cast<double>(grid.size());
}

inline bool HashGrid::BallQuery::visits(const HashGrid& grid, std::uint32_t i) const {
  const Vec3f& p = grid.point(i);
  if (!(d2_of(p, centre_) <= r2_)) return false;
  if (scan_all_) return true;
  // The cell the point was sorted into (build() bins it the same way).
  const double v[3] = {p.x, p.y, p.z};
  for (int a = 0; a < 3; ++a) {
    const std::int64_t cell = grid.clamped_coord(v[a], a);
    if (cell < lo_[a] || cell > hi_[a]) return false;
  }
  return true;
}

template <class Visit>
void HashGrid::for_each_in_ball(const BallQuery& query, Visit&& visit) const {
  // Locals, so that the scan keeps them in registers.
  const Vec3 centre = query.centre_;
  const double r2 = query.r2_;
  const Vec3f* const points = points_.data();
  const std::int64_t* lo = query.lo_;
  const std::int64_t* hi = query.hi_;
  if (query.scan_all_) {
    for (std::uint32_t i = 0; i < points_.size(); ++i) {
      const double d2 = BallQuery::d2_of(points[i], centre);
      if (d2 <= r2) visit(i, d2);
    }
    return;
  }
  static constexpr auto kSlabs = [] {
    std::array<std::array<std::array<std::uint64_t, 4>, 4>, 3> slabs{};
    for (int a = 0; a < 3; ++a) {
      for (int l = 0; l < 4; ++l) {
        for (int h = l; h < 4; ++h) slabs[a][l][h] = block_slab(a, l, h);
      }
    }
    return slabs;
  }();
  // The block's cells in the query's box along one axis.
  const auto slab = [&](int a, std::int64_t block) {
    const std::int64_t first = 4 * block;
    return kSlabs[a][std::max<std::int64_t>(lo[a] - first, 0)]
                 [std::min<std::int64_t>(hi[a] - first, 3)];
  };
  // Points found are buffered and visited after the scan: the inside test then has no
  // unpredictable branch (it decides only whether the buffer slot is kept).
  std::uint32_t found[64];
  double found_d2[64];
  std::size_t count = 0;
  const auto flush = [&] {
    for (std::size_t f = 0; f < count; ++f) visit(found[f], found_d2[f]);
    count = 0;
  };
  // The point ranges to scan are collected first, their first points prefetched, and scanned
  // after: the cache misses of a query's cells then overlap instead of following one another.
  std::uint32_t range_begin[16], range_end[16];
  std::size_t ranges = 0;
  const auto scan = [&] {
    for (std::size_t r = 0; r < ranges; ++r) {
      for (std::uint32_t i = range_begin[r]; i < range_end[r]; ++i) {
        const double d2 = BallQuery::d2_of(points[i], centre);
        found[count] = i;
        found_d2[count] = d2;
        count += d2 <= r2;
        if (count == std::size(found)) flush();
      }
    }
    ranges = 0;
  };
  // Block by block, the non-empty cells in the query's box come from the masks at once; cells
  // consecutive in Morton order have consecutive points, so each run of them is one range.
  for (std::int64_t bz = lo[2] >> 2; bz <= hi[2] >> 2; ++bz) {
    const std::uint64_t mask_z = slab(2, bz);
    for (std::int64_t by = lo[1] >> 2; by <= hi[1] >> 2; ++by) {
      const std::uint64_t mask_yz = mask_z & slab(1, by);
      for (std::int64_t bx = lo[0] >> 2; bx <= hi[0] >> 2; ++bx) {
        const Block* block =
            find_block(morton3(static_cast<std::uint64_t>(bx), static_cast<std::uint64_t>(by),
                               static_cast<std::uint64_t>(bz)));
        if (!block) continue;
        std::uint64_t cells = block->cells & mask_yz & slab(0, bx);
        while (cells) {
          const int start = std::countr_zero(cells);
          const int run = std::countr_one(cells >> start);
          const std::size_t k =
              block->first + bit_count(block->cells & ((std::uint64_t{1} << start) - 1));
          cells = start + run >= 64 ? 0 : cells & (~0ull << (start + run));
          range_begin[ranges] = cell_begin_[k];
          range_end[ranges] = cell_begin_[k + static_cast<std::size_t>(run)];
          __builtin_prefetch(points + range_begin[ranges]);
          if (++ranges == std::size(range_begin)) scan();
        }
      }
    }
  }
  scan();
  flush();
}

template <class Keep>
std::uint32_t HashGrid::nearest(std::uint32_t i, double max_radius, Keep&& keep) const {
  const Vec3 c = position(i);
  // Balls from a quarter cell up, doubling: the first usually holds the nearest point already
  // and spans one or two cells a side, where a ball of a whole cell scans 27 or more (the
  // spacing estimate's 4,096 queries per grid cost three times as much that way).
  for (double r = std::min(cell_ / 4, max_radius);; r = std::min(r * 2, max_radius)) {
    std::uint32_t best = kNoIndex;
    double best_d2 = 0;
    for_each_in_ball(c, r, [&](std::uint32_t j, double d2) {
      if (j == i || !keep(j)) return;
      if (best == kNoIndex || d2 < best_d2 || (d2 == best_d2 && j < best)) best = j, best_d2 = d2;
    });
    if (best != kNoIndex || r >= max_radius) return best;
  }
}

}  // namespace g2s
