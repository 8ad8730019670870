// Builds the hash grid: cell size from the sampling spacing, points radix-sorted into Morton
// order of their cells, duplicates merged, and the block hash filled. See hash_grid.hpp.
#include "grid/hash_grid.hpp"

#include <bit>
#include <cstring>
#include <numeric>

#include "common/sample_spacing.hpp"

namespace g2s {
namespace {

constexpr std::uint64_t kEmpty = ~0ull;
constexpr std::int64_t kMaxDim = (1 << 21) - 2;

// Sorts (key, value) pairs by key with an LSD radix sort over the low key_bits bits. Stable, so
// equal keys keep the order they came in.
void radix_sort(std::vector<std::uint64_t>& keys, std::vector<std::uint32_t>& values,
                int key_bits) {
  constexpr int kDigit = 11;
  const std::size_t n = keys.size();
  std::vector<std::uint64_t> keys_tmp(n);
  std::vector<std::uint32_t> values_tmp(n);
  std::vector<std::uint32_t> count(1u << kDigit);
  for (int shift = 0; shift < key_bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (std::size_t i = 0; i < n; ++i) ++count[keys[i] >> shift & ((1u << kDigit) - 1)];
    std::uint32_t sum = 0;
    for (auto& c : count) {
      const std::uint32_t k = c;
      c = sum;
      sum += k;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t d = keys[i] >> shift & ((1u << kDigit) - 1);
      const std::uint32_t to = count[d]++;
      keys_tmp[to] = keys[i];
      values_tmp[to] = values[i];
    }
    keys.swap(keys_tmp);
    values.swap(values_tmp);
  }
}

int bits_for(std::int64_t v) {
  int b = 1;
  while ((std::int64_t{1} << b) <= v) ++b;
  return b;
}

}  // namespace

HashGrid::HashGrid(std::span<const float> xyz, std::span<const Index> ids, double group_distance,
                   double twin_distance, std::span<const std::uint8_t> keep)
    : group_distance_(group_distance) {
  const std::size_t n = xyz.size() / 3;
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int a = 0; a < 3; ++a) {
    lo[a] = n ? xyz[a] : 0.0;
    hi[a] = lo[a];
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min<double>(lo[a], xyz[3 * i + a]);
      hi[a] = std::max<double>(hi[a], xyz[3 * i + a]);
    }
  }
  for (int a = 0; a < 3; ++a) {
    origin_[a] = lo[a];
    extent_[a] = hi[a] - lo[a];
  }
  const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
  const double extent = std::max({dx, dy, dz});
  // A surface spanning the box has an area of the order of its largest faces.
  double area = dx * dy + dy * dz + dz * dx;
  if (!(area > 0)) area = extent * extent;
  double cell = n > 1 && area > 0 ? 3.0 * std::sqrt(area / static_cast<double>(n)) : 1.0;
  const double min_cell = extent > 0 ? extent / static_cast<double>(kMaxDim) : 1.0;

  build(xyz, ids, std::max(cell, min_cell));
  // In a cloud of twins, a point within twin_distance of one with a smaller id is a near-copy of
  // it: left out, so that the kept one's balls stay empty. Decided by id, so every grid holding
  // both keeps the same one.
  std::vector<float> kept_xyz;
  std::vector<Index> kept_ids;
  std::vector<std::uint32_t> kept_source;
  const std::uint64_t duplicates = duplicates_;
  if (twin_distance > 0) {
    for (std::uint32_t i = 0; i < size(); ++i) {
      bool copy = false;
      if (keep.empty() || keep[sources_[i]] == 0) {
        for_each_in_ball(position(i), twin_distance,
                         [&](std::uint32_t j, double) { copy = copy || ids_[j] < ids_[i]; });
      }
      if (copy) continue;
      kept_xyz.insert(kept_xyz.end(), {points_[i].x, points_[i].y, points_[i].z});
      kept_ids.push_back(ids_[i]);
      kept_source.push_back(sources_[i]);
    }
    twins_ = size() - kept_ids.size();
    if (twins_ > 0) {
      xyz = kept_xyz;
      ids = kept_ids;
      build(xyz, ids, std::max(cell, min_cell));
    }
  }
  estimate_spacing();
  // Rebuild with a cell edge of about three spacings: a front search ball (radius about one edge,
  // which on noisy scans is often twice the nearest-neighbour distance) then spans about two
  // cells per axis, and a cell holds about ten surface points, scanned sequentially. Always
  // rebuilt, so the cell size, and with it the point order and the mesh, depend only on the
  // distinct points, not on duplicates or on the first guess.
  if (spacing_ > 0) build(xyz, ids, std::max(3.0 * spacing_, min_cell));
  if (twins_ > 0) {
    for (std::uint32_t& source : sources_) source = kept_source[source];
    duplicates_ = duplicates;
  }
}

void HashGrid::build(std::span<const float> xyz, std::span<const Index> ids, double cell) {
  const std::size_t n = xyz.size() / 3;
  cell_ = cell;
  inv_cell_ = 1.0 / cell;
  std::int64_t max_dim = 1;
  for (int a = 0; a < 3; ++a) {
    dims_[a] = std::min(cell_coord(origin_[a] + extent_[a], a) + 1, kMaxDim + 1);
    max_dim = std::max(max_dim, dims_[a]);
  }

  std::vector<std::uint64_t> codes(n);
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  auto coord = [&](std::size_t i, int a) {
    return static_cast<std::uint64_t>(
        std::clamp<std::int64_t>(cell_coord(xyz[3 * i + a], a), 0, dims_[a] - 1));
  };
  for (std::size_t i = 0; i < n; ++i) codes[i] = morton3(coord(i, 0), coord(i, 1), coord(i, 2));
  radix_sort(codes, order, 3 * bits_for(max_dim));

  auto id_of = [&](std::uint32_t i) { return ids.empty() ? i : ids[i]; };
  auto less = [&](std::uint32_t i, std::uint32_t j) {
    for (int a = 0; a < 3; ++a) {
      if (xyz[3 * i + a] != xyz[3 * j + a]) return xyz[3 * i + a] < xyz[3 * j + a];
    }
    return id_of(i) < id_of(j);
  };
  auto same = [&](std::uint32_t i, std::uint32_t j) {
    return xyz[3 * i] == xyz[3 * j] && xyz[3 * i + 1] == xyz[3 * j + 1] &&
           xyz[3 * i + 2] == xyz[3 * j + 2];
  };

  points_.clear();
  ids_.clear();
  sources_.clear();
  cell_begin_.clear();
  points_.reserve(n);
  ids_.reserve(n);
  sources_.reserve(n);
  std::vector<std::uint64_t> cell_codes;
  duplicates_ = 0;
  // Within a cell: order by coordinates, then id, so the result does not depend on input order
  // and exact duplicates are adjacent.
  for (std::size_t begin = 0; begin < n;) {
    std::size_t end = begin + 1;
    while (end < n && codes[end] == codes[begin]) ++end;
    std::sort(order.begin() + begin, order.begin() + end, less);
    cell_codes.push_back(codes[begin]);
    cell_begin_.push_back(static_cast<std::uint32_t>(points_.size()));
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t i = order[k];
      if (k > begin && same(i, order[k - 1])) {
        ++duplicates_;
        continue;
      }
      points_.push_back({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]});
      ids_.push_back(id_of(i));
      sources_.push_back(i);
    }
    begin = end;
  }
  cell_begin_.push_back(static_cast<std::uint32_t>(points_.size()));

  // Blocks in Morton order: a block's cells are consecutive in cell_codes.
  std::vector<Block> blocks;
  for (std::size_t c = 0; c < cell_codes.size(); ++c) {
    if (blocks.empty() || blocks.back().code != cell_codes[c] >> 6) {
      blocks.push_back({cell_codes[c] >> 6, 0, static_cast<std::uint32_t>(c)});
    }
    blocks.back().cells |= std::uint64_t{1} << (cell_codes[c] & 63);
  }
  std::size_t slots = 16;
  while (slots < 2 * blocks.size()) slots *= 2;
  slot_mask_ = slots - 1;
  slot_shift_ = 64 - std::countr_zero(slots);
  blocks_.assign(slots, Block{kEmpty, 0, 0});
  for (const Block& b : blocks) {
    std::uint64_t slot = slot_of(b.code);
    while (blocks_[slot].code != kEmpty) slot = (slot + 1) & slot_mask_;
    blocks_[slot] = b;
  }
}

void HashGrid::estimate_spacing() {
  spacing_ = spacing_lower_bound_ = 0.0;
  const std::uint32_t n = size();
  if (n < 2) return;
  // Samples are chosen by a hash of their coordinates, not their place in the grid order, so
  // the estimate does not depend on the first cell size. A point with no neighbour within 64
  // cells is an outlier and is left out rather than searched for across empty space.
  const std::uint64_t threshold = n <= 4096 ? ~0ull : (~0ull / n) * 4096;
  const double max_radius = 64 * cell_;
  std::vector<double> d;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec3f& p = points_[i];
    std::uint32_t bits[3];
    std::memcpy(bits, &p, sizeof bits);
    std::uint64_t h = (std::uint64_t{bits[0]} << 32 | bits[1]) ^ (std::uint64_t{bits[2]} << 16);
    h ^= h >> 31;
    h *= 0x9E3779B97F4A7C15ull;
    h ^= h >> 29;
    if (h > threshold) continue;
    if (group_distance_ == 0) {
      const std::uint32_t j = nearest(i, max_radius, [](std::uint32_t) { return true; });
      if (j != kNoIndex) d.push_back(std::sqrt(norm2(position(i) - position(j))));
      continue;
    }
    // Points in groups: the nearest beyond the cloud's group distance, among the three nearest
    // (balls from a quarter cell up, doubling, until one holds three other points or reaches
    // max_radius).
    NearestThree squared;
    for (double r = std::min(cell_ / 4, max_radius);; r = std::min(r * 2, max_radius)) {
      squared = {};
      for_each_in_ball(position(i), r, [&](std::uint32_t j, double d2) {
        if (j != i) squared.offer(d2);
      });
      if (squared.third() <= r * r || r >= max_radius) break;
    }
    NearestThree sample;
    for (int k = 0; k < 3; ++k) sample.d[k] = std::sqrt(squared.d[k]);
    const double beyond = distance_beyond(sample, group_distance_);
    if (beyond != std::numeric_limits<double>::infinity()) d.push_back(beyond);
  }
  if (d.empty()) return;
  // The median: robust to outliers and to the few isolated points every scan has.
  const std::size_t middle = d.size() / 2;
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(middle), d.end());
  spacing_ = d[middle];
  // The number of sampled distances below the true median is binomial (m, 1/2): it falls under
  // m/2 - 1.96 sqrt(m)/2 with probability 2.5% (normal approximation).
  const double half_width = 0.98 * std::sqrt(static_cast<double>(d.size()));
  const auto lower =
      static_cast<std::size_t>(std::max(0.0, std::floor(static_cast<double>(middle) - half_width)));
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(lower),
                   d.begin() + static_cast<std::ptrdiff_t>(middle));
  spacing_lower_bound_ = d[lower];
}

}  // namespace g2s
