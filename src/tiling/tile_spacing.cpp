// Tile spacing estimate (see tile_spacing.hpp): the points are bucketed by cell once; a sampled
// point's nearest neighbour is searched in shells of cells around its own, stopping
// once the best distance found is within the searched cube, so the answer is exact.
#include "tiling/tile_spacing.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace g2s::tiling {
namespace {

constexpr std::size_t kSamples = 4096;
constexpr std::int64_t kMaxShell = 16;
constexpr std::int64_t kMaxCells = (std::int64_t{1} << 21) - 1;  // per axis: 21-bit keys

std::uint64_t cell_key(std::int64_t x, std::int64_t y, std::int64_t z) {
  return static_cast<std::uint64_t>(x) << 42 | static_cast<std::uint64_t>(y) << 21 |
         static_cast<std::uint64_t>(z);
}

}  // namespace

double estimate_tile_spacing(std::span<const double> xyz) {
  const std::size_t n = xyz.size() / 3;
  if (n < 2) return 0.0;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = hi[a] = xyz[a];
  for (std::size_t i = 1; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], xyz[3 * i + a]);
      hi[a] = std::max(hi[a], xyz[3 * i + a]);
    }
  }
  const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
  const double extent = std::max({dx, dy, dz});
  if (!(extent > 0)) return 0.0;
  // A surface sample: the area is of the order of the box's largest faces; a line has none.
  const double area = dx * dy + dy * dz + dz * dx;
  double cell = area > 0 ? 2.0 * std::sqrt(area / static_cast<double>(n))
                         : 2.0 * extent / static_cast<double>(n);
  cell = std::max(cell, extent / static_cast<double>(kMaxCells - 1));
  const double inv_cell = 1.0 / cell;
  auto coord = [&](double v, int a) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>((v - lo[a]) * inv_cell), 0,
                                    kMaxCells - 1);
  };

  // Points bucketed by a hash of their cell (a counting sort, O(n)). Cells sharing a bucket
  // only add candidates: distances are computed exactly, so the answer is unchanged.
  std::size_t buckets = 64;
  while (buckets < 2 * n) buckets *= 2;
  const int bucket_shift = 64 - std::countr_zero(buckets);
  auto bucket_of = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::size_t>((cell_key(x, y, z) * 0x9E3779B97F4A7C15ull) >> bucket_shift);
  };
  std::vector<std::uint32_t> bucket_start(buckets + 1, 0);
  std::vector<std::uint32_t> point_bucket(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = &xyz[3 * i];
    point_bucket[i] =
        static_cast<std::uint32_t>(bucket_of(coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)));
    ++bucket_start[point_bucket[i] + 1];
  }
  for (std::size_t b = 0; b < buckets; ++b) bucket_start[b + 1] += bucket_start[b];
  std::vector<std::uint32_t> bucketed(n);
  {
    std::vector<std::uint32_t> fill(bucket_start.begin(), bucket_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      bucketed[fill[point_bucket[i]]++] = static_cast<std::uint32_t>(i);
  }

  const std::size_t step = (n + kSamples - 1) / kSamples;
  double sum = 0.0;
  std::size_t found = 0;
  for (std::size_t s = 0; s < n; s += step) {
    const double* p = &xyz[3 * s];
    const std::int64_t c[3] = {coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)};
    double best2 = std::numeric_limits<double>::infinity();
    bool exact = false;
    for (std::int64_t r = 0; r <= kMaxShell; ++r) {
      for (std::int64_t x = c[0] - r; x <= c[0] + r; ++x) {
        for (std::int64_t y = c[1] - r; y <= c[1] + r; ++y) {
          for (std::int64_t z = c[2] - r; z <= c[2] + r; ++z) {
            const std::int64_t shell =
                std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])});
            if (shell != r || x < 0 || y < 0 || z < 0 || x >= kMaxCells || y >= kMaxCells ||
                z >= kMaxCells) {
              continue;
            }
            const std::size_t b = bucket_of(x, y, z);
            for (std::uint32_t k = bucket_start[b]; k < bucket_start[b + 1]; ++k) {
              const double* q = &xyz[3 * bucketed[k]];
              const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                (p[2] - q[2]) * (p[2] - q[2]);
              if (d2 > 0 && d2 < best2) best2 = d2;
            }
          }
        }
      }
      // Every point outside the searched cube is at least r cells away.
      const double reach = static_cast<double>(r) * cell;
      if (best2 <= reach * reach) {
        exact = true;
        break;
      }
    }
    if (exact) {
      sum += std::sqrt(best2);
      ++found;
    }
  }
  return found > 0 ? sum / static_cast<double>(found) : 0.0;
}

}  // namespace g2s::tiling
