// Flat hash grid for fixed-radius neighbour search (ALGORITHM.md §2). Points are sorted once
// into Morton order of their cells (a radix sort), so a cell's points are contiguous and
// neighbouring cells lie close in memory; non-empty cells are found through an open-addressing
// hash of their 4x4x4 blocks' Morton codes, so empty space costs nothing. Exact duplicate points
// are merged while sorting (the one with the smallest id is kept).
#pragma once

#include <algorithm>
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
  // edge is chosen from the estimated sampling spacing.
  HashGrid(std::span<const float> xyz, std::span<const Index> ids);

  std::uint32_t size() const { return static_cast<std::uint32_t>(points_.size()); }
  const Vec3f& point(std::uint32_t i) const { return points_[i]; }
  Vec3 position(std::uint32_t i) const { return Vec3(points_[i]); }
  Index id(std::uint32_t i) const { return ids_[i]; }
  std::span<const Vec3f> points() const { return points_; }
  std::uint64_t duplicates_merged() const { return duplicates_; }
  double spacing() const { return spacing_; }  // mean nearest-neighbour distance (sampled)
  double cell_size() const { return cell_; }

  // Calls visit(i, squared distance) for every point within radius of centre.
  template <class Visit>
  void for_each_in_ball(const Vec3& centre, double radius, Visit&& visit) const;

  // Nearest point to point i among those accepted by keep(j), within max_radius; kNoIndex if
  // none.
  template <class Keep>
  std::uint32_t nearest(std::uint32_t i, double max_radius, Keep&& keep) const;

 private:
  void build(std::span<const float> xyz, std::span<const Index> ids, double cell);
  double estimate_spacing() const;
  std::int64_t cell_coord(double v, int axis) const {
    return static_cast<std::int64_t>(std::floor((v - origin_[axis]) * inv_cell_));
  }
  // The coordinate of the query cell (2x2x2 cells) holding v, clamped to the grid; clamped
  // first, so that a cast rounds the same as floor (no call to floor: queries compute several
  // per row).
  std::int64_t query_coord(double v, int axis) const {
    const double c = (v - origin_[axis]) * (0.5 * inv_cell_);
    return static_cast<std::int64_t>(
        std::min(std::max(c, 0.0), static_cast<double>((dims_[axis] - 1) / 2)));
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
  std::uint64_t duplicates_ = 0;
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

template <class Visit>
void HashGrid::for_each_in_ball(const Vec3& centre, double radius, Visit&& visit) const {
  const double r2 = radius * radius;
  // Queries visit cells of 2x2x2 grid cells (6 spacings): their 8 cells are consecutive in Morton
  // order, so their points are one range, found from the block's mask. The grid's own cells (3
  // spacings) give the point order (and so the seeds' order and every tie-break by index); a
  // front query, typically 1-2 spacings in radius on noisy scans, costs less over fewer,
  // fuller cells. Only the cells the ball touches: per z slab and y row, the x range shrinks to
  // the ball's chord there.
  const double size = 2 * cell_;
  auto gap = [&](std::int64_t cell, double c, int axis) {  // distance from c to a cell's span
    const double lo = origin_[axis] + static_cast<double>(cell) * size;
    return c < lo ? lo - c : std::max(0.0, c - (lo + size));
  };
  const std::int64_t z0 = query_coord(centre.z - radius, 2);
  const std::int64_t z1 = query_coord(centre.z + radius, 2);
  // A ball spanning more cells than there are points (far outliers, very uneven density) is
  // cheaper to answer by scanning the points than by probing mostly empty cells.
  double box_cells = static_cast<double>(z1 - z0 + 1);
  for (int a = 0; a < 2; ++a) {
    const double c = a == 0 ? centre.x : centre.y;
    box_cells *= static_cast<double>(query_coord(c + radius, a) - query_coord(c - radius, a) + 1);
  }
  if (box_cells > static_cast<double>(points_.size())) {
    for (std::uint32_t i = 0; i < points_.size(); ++i) {
      const Vec3f& p = points_[i];
      const double dx = p.x - centre.x, dy = p.y - centre.y, dz = p.z - centre.z;
      const double d2 = dx * dx + dy * dy + dz * dz;
      if (d2 <= r2) visit(i, d2);
    }
    return;
  }
  // Points found are buffered and visited after the scan: the inside test then has no
  // unpredictable branch (it decides only whether the buffer slot is kept).
  std::uint32_t found[64];
  double found_d2[64];
  std::size_t count = 0;
  const auto flush = [&] {
    for (std::size_t f = 0; f < count; ++f) visit(found[f], found_d2[f]);
    count = 0;
  };
  // The query's blocks (2x2x2 query cells each), each looked up once: they are told apart by the
  // parities of their coordinates (a query spans at most two blocks per axis unless its radius
  // exceeds a block).
  std::uint64_t block_code[8];
  const Block* block_of[8] = {};
  std::fill(std::begin(block_code), std::end(block_code), ~0ull);
  for (std::int64_t z = z0; z <= z1; ++z) {
    const double gz = gap(z, centre.z, 2);
    const double rz2 = r2 - gz * gz;
    if (rz2 < 0) continue;
    const double rz = std::sqrt(rz2);
    const std::int64_t y0 = query_coord(centre.y - rz, 1);
    const std::int64_t y1 = query_coord(centre.y + rz, 1);
    const std::uint64_t code_z = morton3(0, 0, static_cast<std::uint64_t>(2 * z));
    for (std::int64_t y = y0; y <= y1; ++y) {
      const double gy = gap(y, centre.y, 1);
      const double ry2 = rz2 - gy * gy;
      if (ry2 < 0) continue;
      const double ry = std::sqrt(ry2);
      const std::int64_t x0 = query_coord(centre.x - ry, 0);
      const std::int64_t x1 = query_coord(centre.x + ry, 0);
      const std::uint64_t code_yz = code_z | morton3(0, static_cast<std::uint64_t>(2 * y), 0);
      for (std::int64_t x = x0; x <= x1; ++x) {
        // The Morton code of the query cell's first grid cell; its 8 cells follow.
        const std::uint64_t code = code_yz | morton3(static_cast<std::uint64_t>(2 * x), 0, 0);
        const std::uint64_t bc = code >> 6;
        const std::size_t slot = (bc & 1) | (bc >> 2 & 2) | (bc >> 4 & 4);
        if (block_code[slot] != bc) block_code[slot] = bc, block_of[slot] = find_block(bc);
        const Block* block = block_of[slot];
        if (!block) continue;
        const unsigned shift = code & 63;
        const std::uint64_t cells = block->cells >> shift & 0xFF;
        if (!cells) continue;
        const std::size_t k =
            block->first + bit_count(block->cells & ((std::uint64_t{1} << shift) - 1));
        for (std::uint32_t i = cell_begin_[k], end = cell_begin_[k + bit_count(cells)]; i < end;
             ++i) {
          const Vec3f& p = points_[i];
          const double dx = p.x - centre.x, dy = p.y - centre.y, dz = p.z - centre.z;
          const double d2 = dx * dx + dy * dy + dz * dz;
          found[count] = i;
          found_d2[count] = d2;
          count += d2 <= r2;
          if (count == std::size(found)) flush();
        }
      }
    }
  }
  flush();
}

template <class Keep>
std::uint32_t HashGrid::nearest(std::uint32_t i, double max_radius, Keep&& keep) const {
  const Vec3 c = position(i);
  for (double r = std::min(cell_, max_radius);; r = std::min(r * 2, max_radius)) {
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
