// Self-intersection count of compute_stats: candidate pairs from a uniform grid, each checked with
// the exact test of common/triangle_intersection.hpp after the first triangle's separating
// planes (common/separating_planes.hpp), which settle most neighbours without it.
// - Every triangle gets a float bounding box rounded outwards (half the memory of doubles, and a
//   box only has to contain the triangle), relative to the mesh's low corner: georeferenced
//   coordinates (1e6-1e7) would otherwise round every box of a millimetre-spaced scan to half a
//   metre, and a bucket would hold the whole scan (raw-bunny moved to UTM-sized coordinates: no
//   answer in 4 minutes, against a second).
// - The grid's cell is three times the mean of the boxes' largest sides (on raw-bunny's mesh, 1x
//   took 50% more time than 2x, and 3x or 4x about 10% less: fewer entries against more box
//   tests per bucket). A triangle is entered in the buckets of the cells its box overlaps; cells
//   are hashed into a power-of-two bucket table (empty space costs nothing), and a triangle
//   enters a bucket once even when two of its cells hash to it. Buckets are filled by a counting
//   sort: flat arrays, no per-cell allocation.
// - Two triangles are compared in every bucket they share, but the pair is taken only in the
//   bucket of the cell holding the low corner of their boxes' overlap, which both boxes contain:
//   each overlapping pair is tested exactly once, whatever the threads do.
// - A triangle whose box spans more than kMaxCells cells (a long sliver, a far outlier) stays out
//   of the grid and is compared with every triangle: rare in meshes of scans, and correct always.
#include "stats/self_intersections.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "common/mix64.hpp"
#include "common/separating_planes.hpp"
#include "common/triangle_intersection.hpp"

namespace g2s::stats {
namespace {

constexpr int kMaxCells = 64;                  // cells of one triangle's box in the grid
constexpr double kMaxCellCoordinate = 0x1p40;  // cell coordinates stay well inside int64

struct Box {
  float lo[3], hi[3];
};

// The float just at or below d - origin, and just at or above it: the subtraction's own rounding
// is stepped over first, so the box holds the exact difference.
float below(double d, double origin) {
  const double shifted = std::nextafter(d - origin, -std::numeric_limits<double>::infinity());
  const auto f = static_cast<float>(shifted);
  return static_cast<double>(f) > shifted
             ? std::nextafter(f, -std::numeric_limits<float>::infinity())
             : f;
}
float above(double d, double origin) {
  const double shifted = std::nextafter(d - origin, std::numeric_limits<double>::infinity());
  const auto f = static_cast<float>(shifted);
  return static_cast<double>(f) < shifted
             ? std::nextafter(f, std::numeric_limits<float>::infinity())
             : f;
}

bool overlap(const Box& a, const Box& b) {
  for (int k = 0; k < 3; ++k) {
    if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
  }
  return true;
}

class Grid {
 public:
  Grid(const float origin[3], double cell) : inv_cell_(1.0 / cell) {
    for (int k = 0; k < 3; ++k) origin_[k] = origin[k];
  }
  // The cell coordinate of v along axis k: monotonic in v, so a box's cells are a range.
  double cell(float v, int k) const {
    return std::floor((static_cast<double>(v) - origin_[k]) * inv_cell_);
  }
  // The number of cells the box overlaps, or 0 when it is too many (or too far) for the grid.
  std::uint64_t cell_count(const Box& box) const {
    std::uint64_t count = 1;
    for (int k = 0; k < 3; ++k) {
      const double lo = cell(box.lo[k], k), hi = cell(box.hi[k], k);
      if (!(lo >= -kMaxCellCoordinate && hi <= kMaxCellCoordinate)) return 0;
      count *= static_cast<std::uint64_t>(hi - lo) + 1;
      if (count > kMaxCells) return 0;
    }
    return count;
  }
  void set_buckets(std::uint64_t buckets) { mask_ = buckets - 1; }
  std::uint64_t bucket(std::int64_t x, std::int64_t y, std::int64_t z) const {
    const auto ux = static_cast<std::uint64_t>(x), uy = static_cast<std::uint64_t>(y),
               uz = static_cast<std::uint64_t>(z);
    return mix64(ux * 0x9e3779b97f4a7c15ULL ^ uy * 0xc2b2ae3d27d4eb4fULL ^
                 uz * 0x165667b19e3779f9ULL) &
           mask_;
  }
  std::uint64_t bucket_of_point(const float p[3]) const {
    return bucket(static_cast<std::int64_t>(cell(p[0], 0)),
                  static_cast<std::int64_t>(cell(p[1], 1)),
                  static_cast<std::int64_t>(cell(p[2], 2)));
  }
  // The distinct buckets of the box's cells (cell_count(box) of them at most), sorted.
  int buckets_of(const Box& box, std::uint32_t* out) const {
    std::int64_t lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = static_cast<std::int64_t>(cell(box.lo[k], k));
      hi[k] = static_cast<std::int64_t>(cell(box.hi[k], k));
    }
    int n = 0;
    for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
      for (std::int64_t y = lo[1]; y <= hi[1]; ++y) {
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
          out[n++] = static_cast<std::uint32_t>(bucket(x, y, z));
        }
      }
    }
    std::sort(out, out + n);
    return static_cast<int>(std::unique(out, out + n) - out);
  }

 private:
  double origin_[3];
  double inv_cell_;
  std::uint64_t mask_ = 0;
};

struct Counts {
  std::uint64_t pairs = 0, pairs_no_shared_vertex = 0;
  void operator+=(const Counts& o) {
    pairs += o.pairs;
    pairs_no_shared_vertex += o.pairs_no_shared_vertex;
  }
};

}  // namespace

CrossingCounts count_crossings(std::span<const Triangle> triangles, const double* xyz,
                               std::span<const Index> rep) {
  const std::size_t count = triangles.size();
  auto corner = [&](Index w) { return xyz + 3 * std::size_t{rep[w]}; };
  auto kept = [&](std::size_t t) { return triangles[t][0] != kNoIndex; };

  // The low corner of the kept triangles' finite corners, in input order.
  double mesh_low[3] = {std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity()};
  for (std::size_t t = 0; t < count; ++t) {
    if (!kept(t)) continue;
    for (const Index w : triangles[t]) {
      for (int k = 0; k < 3; ++k) {
        if (std::isfinite(corner(w)[k])) mesh_low[k] = std::min(mesh_low[k], corner(w)[k]);
      }
    }
  }
  for (double& l : mesh_low) {
    if (!std::isfinite(l)) l = 0;
  }
  // Boxes; a triangle with a non-finite coordinate is left out (its box stays empty: lo > hi).
  std::vector<Box> boxes(count);
  std::vector<std::uint8_t> usable(count, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 4096), [&](const auto& range) {
    for (std::size_t t = range.begin(); t < range.end(); ++t) {
      if (!kept(t)) continue;
      double lo[3], hi[3];
      bool finite = true;
      for (int k = 0; k < 3; ++k) {
        const double a = corner(triangles[t][0])[k], b = corner(triangles[t][1])[k],
                     c = corner(triangles[t][2])[k];
        lo[k] = std::min({a, b, c});
        hi[k] = std::max({a, b, c});
        // Each corner: min and max pass a NaN over when it is not first.
        finite = finite && std::isfinite(a) && std::isfinite(b) && std::isfinite(c);
      }
      if (!finite) continue;
      usable[t] = 1;
      for (int k = 0; k < 3; ++k) {
        boxes[t].lo[k] = below(lo[k], mesh_low[k]);
        boxes[t].hi[k] = above(hi[k], mesh_low[k]);
      }
    }
  });

  // The grid: origin at the boxes' low corner, cell three times their mean largest side (in input
  // order, so the same for any thread count).
  float origin[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                     std::numeric_limits<float>::infinity()};
  double side_sum = 0.0;
  std::size_t boxed = 0;
  for (std::size_t t = 0; t < count; ++t) {
    if (!usable[t]) continue;
    const Box& b = boxes[t];
    const double side =
        std::max({static_cast<double>(b.hi[0]) - b.lo[0], static_cast<double>(b.hi[1]) - b.lo[1],
                  static_cast<double>(b.hi[2]) - b.lo[2]});
    if (!std::isfinite(side)) continue;  // beyond float's range: out of the grid below
    side_sum += side;
    ++boxed;
    for (int k = 0; k < 3; ++k) origin[k] = std::min(origin[k], b.lo[k]);
  }
  double cell = 3.0 * side_sum / static_cast<double>(boxed);
  if (!(cell > 0.0) || !std::isfinite(cell)) cell = 1.0;

  // Cells per triangle (0: out of the grid), then a bucket table half as large as the entries.
  Grid grid(origin, cell);
  std::vector<std::uint8_t> cells(count, 0);
  const std::uint64_t entries = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, count, 4096), std::uint64_t{0},
      [&](const auto& range, std::uint64_t sum) {
        for (std::size_t t = range.begin(); t < range.end(); ++t) {
          if (!usable[t]) continue;
          cells[t] = static_cast<std::uint8_t>(grid.cell_count(boxes[t]));
          sum += cells[t];
        }
        return sum;
      },
      std::plus<>());
  const std::uint64_t bucket_count = std::bit_ceil(std::max<std::uint64_t>(entries / 2, 1024));
  grid.set_buckets(bucket_count);
  if (entries >= std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error("self-intersection grid: more than 2^32 entries");
  }

  // Counting sort of (bucket, triangle) entries: count, prefix sums, fill.
  auto for_each_entry = [&](auto&& visit) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 4096), [&](const auto& range) {
      std::uint32_t buckets[kMaxCells];
      for (std::size_t t = range.begin(); t < range.end(); ++t) {
        if (cells[t] == 0) continue;
        const int n = grid.buckets_of(boxes[t], buckets);
        for (int i = 0; i < n; ++i) visit(buckets[i], static_cast<Index>(t));
      }
    });
  };
  std::vector<std::uint32_t> offset(bucket_count + 1, 0);
  for_each_entry([&](std::uint32_t bucket, Index) {
    std::atomic_ref<std::uint32_t>(offset[bucket + 1]).fetch_add(1, std::memory_order_relaxed);
  });
  for (std::uint64_t b = 0; b < bucket_count; ++b) offset[b + 1] += offset[b];
  std::vector<Index> entry(offset[bucket_count]);
  {
    std::vector<std::uint32_t> fill(offset.begin(), offset.end() - 1);
    for_each_entry([&](std::uint32_t bucket, Index t) {
      entry[std::atomic_ref<std::uint32_t>(fill[bucket]).fetch_add(1, std::memory_order_relaxed)] =
          t;
    });
  }

  std::vector<std::uint8_t> crossing(count, 0);
  const auto position = [&](Index w) {
    const double* p = corner(w);
    return Vec3{p[0], p[1], p[2]};
  };
  // s's separating planes settle most pairs of neighbours before the exact test.
  auto test = [&](Index s, const SeparatingPlanes& planes, Index t, Counts& c) {
    const Triangle& a = triangles[s];
    const Triangle& b = triangles[t];
    if (planes.separate(b, position)) return;
    const double* const a_corners[3] = {corner(a[0]), corner(a[1]), corner(a[2])};
    const double* const b_corners[3] = {corner(b[0]), corner(b[1]), corner(b[2])};
    if (!triangles_cross(a_corners, b_corners)) return;
    ++c.pairs;
    bool shares = false;
    for (const Index v : a) shares = shares || v == b[0] || v == b[1] || v == b[2];
    if (!shares) ++c.pairs_no_shared_vertex;
    std::atomic_ref<std::uint8_t>(crossing[s]).store(1, std::memory_order_relaxed);
    std::atomic_ref<std::uint8_t>(crossing[t]).store(1, std::memory_order_relaxed);
  };

  auto add_counts = [](Counts a, const Counts& b) {
    a += b;
    return a;
  };
  // Pairs within each bucket, taken in the bucket of their overlap's low corner. The bucket's
  // boxes are first copied side by side (a per-thread buffer that only grows) and sorted by
  // their lower x, so each box is compared only with those that start before it ends in x (a
  // sweep), read from cache instead of from all over the box table.
  struct Entry {
    Box box;
    Index triangle;
  };
  tbb::enumerable_thread_specific<std::vector<Entry>> scratch;
  Counts total = tbb::parallel_reduce(
      tbb::blocked_range<std::uint64_t>(0, bucket_count, 256), Counts{},
      [&](const auto& range, Counts c) {
        std::vector<Entry>& local = scratch.local();
        for (std::uint64_t b = range.begin(); b < range.end(); ++b) {
          const std::uint32_t begin = offset[b], size = offset[b + 1] - begin;
          if (size < 2) continue;
          if (local.size() < size) local.resize(size);
          for (std::uint32_t i = 0; i < size; ++i) {
            local[i] = {boxes[entry[begin + i]], entry[begin + i]};
          }
          std::sort(local.begin(), local.begin() + size, [](const Entry& x, const Entry& y) {
            return x.box.lo[0] < y.box.lo[0] ||
                   (x.box.lo[0] == y.box.lo[0] && x.triangle < y.triangle);
          });
          for (std::uint32_t i = 0; i < size; ++i) {
            const Box& box_s = local[i].box;
            std::optional<SeparatingPlanes> planes;  // built at its first pair
            for (std::uint32_t j = i + 1; j < size && local[j].box.lo[0] <= box_s.hi[0]; ++j) {
              const Box& box_t = local[j].box;
              if (!overlap(box_s, box_t)) continue;
              const float low[3] = {std::max(box_s.lo[0], box_t.lo[0]),
                                    std::max(box_s.lo[1], box_t.lo[1]),
                                    std::max(box_s.lo[2], box_t.lo[2])};
              if (grid.bucket_of_point(low) != b) continue;
              if (!planes) planes.emplace(triangles[local[i].triangle], position);
              test(local[i].triangle, *planes, local[j].triangle, c);
            }
          }
        }
        return c;
      },
      add_counts);

  // Triangles out of the grid against every other (pairs of two such once).
  std::vector<Index> outside;
  for (std::size_t t = 0; t < count; ++t) {
    if (usable[t] && cells[t] == 0) outside.push_back(static_cast<Index>(t));
  }
  total += tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, outside.size(), 1), Counts{},
      [&](const auto& range, Counts c) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          const Index s = outside[i];
          const SeparatingPlanes planes(triangles[s], position);
          for (std::size_t t = 0; t < count; ++t) {
            if (!usable[t] || t == s || (cells[t] == 0 && t < s)) continue;
            if (overlap(boxes[s], boxes[t])) test(s, planes, static_cast<Index>(t), c);
          }
        }
        return c;
      },
      add_counts);

  CrossingCounts result;
  result.pairs = total.pairs;
  result.pairs_no_shared_vertex = total.pairs_no_shared_vertex;
  for (const std::uint8_t flag : crossing) result.triangles += flag;
  return result;
}

}  // namespace g2s::stats
