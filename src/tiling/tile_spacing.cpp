// Tile spacing estimates (see tile_spacing.hpp): the points are bucketed by cell once; a sampled
// point's three nearest neighbours are searched in shells of cells around its own, skipping
// cells beyond the third distance found so far and stopping once that distance is within the
// searched cube, so the answer is exact.
#include "tiling/tile_spacing.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "common/mix64.hpp"
#include "common/sample_spacing.hpp"
#include "tiling/store_format.hpp"

namespace g2s::tiling {
namespace {

constexpr std::size_t kSamples = 4096;
constexpr std::uint64_t kCloudSamples = 65536;
constexpr double kSeamMargin = 4;
constexpr std::int64_t kMaxShell = 16;
constexpr std::int64_t kMaxCells = (std::int64_t{1} << 21) - 1;  // per axis: 21-bit keys

std::uint64_t cell_key(std::int64_t x, std::int64_t y, std::int64_t z) {
  return static_cast<std::uint64_t>(x) << 42 | static_cast<std::uint64_t>(y) << 21 |
         static_cast<std::uint64_t>(z);
}

// A tile's points bucketed by a hash of their cell, for exact nearest-neighbour searches.
class NeighbourCells {
 public:
  explicit NeighbourCells(std::span<const double> xyz) : xyz_(xyz), n_(xyz.size() / 3) {
    if (n_ < 2) return;
    for (int a = 0; a < 3; ++a) lo_[a] = hi_[a] = xyz[a];
    for (std::size_t i = 1; i < n_; ++i) {
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], xyz[3 * i + a]);
        hi_[a] = std::max(hi_[a], xyz[3 * i + a]);
      }
    }
    const double dx = hi_[0] - lo_[0], dy = hi_[1] - lo_[1], dz = hi_[2] - lo_[2];
    const double extent = std::max({dx, dy, dz});
    if (!(extent > 0)) return;
    // A surface sample: the area is of the order of the box's largest faces; a line has none.
    const double area = dx * dy + dy * dz + dz * dx;
    cell_ = area > 0 ? 2.0 * std::sqrt(area / static_cast<double>(n_))
                     : 2.0 * extent / static_cast<double>(n_);
    cell_ = std::max(cell_, extent / static_cast<double>(kMaxCells - 1));
    inv_cell_ = 1.0 / cell_;
    // Points bucketed by a hash of their cell (a counting sort, O(n)). Cells sharing a bucket
    // only add candidates: distances are computed exactly, so the answer is unchanged. A cell
    // holds about four points of a surface, so half as many buckets as points is about two per
    // cell, and the counts fit in cache: the counting sort's scattered increments were most of
    // the store's spacing pass on tiles of 400k points (the 20M torus's tile command, user time
    // 2.3 -> 2.0 s, against twice as many buckets as points).
    std::size_t buckets = 64;
    while (buckets < n_ / 2) buckets *= 2;
    bucket_shift_ = 64 - std::countr_zero(buckets);
    bucket_start_.assign(buckets + 1, 0);
    std::vector<std::uint32_t> point_bucket(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      const double* p = &xyz[3 * i];
      point_bucket[i] =
          static_cast<std::uint32_t>(bucket_of(coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)));
      ++bucket_start_[point_bucket[i] + 1];
    }
    for (std::size_t b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
    // The coordinates themselves in bucket order: a cell's points are read from one run of
    // memory, not gathered from the whole tile.
    bucketed_.resize(3 * n_);
    std::vector<std::uint32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
    for (std::size_t i = 0; i < n_; ++i) {
      std::copy_n(&xyz[3 * i], 3, &bucketed_[3 * fill[point_bucket[i]]++]);
    }
    scanned_.assign(buckets, 0);
  }

  bool usable() const { return inv_cell_ > 0; }

  // The distances from point i to its three nearest distinct neighbours, exact, or infinity
  // for those not within kMaxShell cells (an outlier has none).
  NearestThree nearest_three(std::size_t i) {
    // Two cells of the search may share a bucket: each bucket is read once a search, or its
    // points would be offered twice and fill two of the three places.
    if (++search_ == 0) {
      std::fill(scanned_.begin(), scanned_.end(), 0);
      search_ = 1;
    }
    const double* p = &xyz_[3 * i];
    const std::int64_t c[3] = {coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)};
    // The point's place in its cell, per axis, less a slack far above the rounding of coord():
    // a cell's points lie no nearer than these bounds say, so skipping a cell or stopping by
    // them never changes the answer.
    double below[3], above[3];
    for (int a = 0; a < 3; ++a) {
      const double offset = p[a] - lo_[a], slack = 1e-9 * (cell_ + std::abs(offset));
      below[a] = offset - static_cast<double>(c[a]) * cell_ - slack;
      above[a] = static_cast<double>(c[a] + 1) * cell_ - offset - slack;
    }
    // Distance from the point to the cells `d` steps away along axis a (0 within), and its
    // square.
    const auto gap = [&](int a, std::int64_t d) {
      const double g = d < 0   ? below[a] + static_cast<double>(-d - 1) * cell_
                       : d > 0 ? above[a] + static_cast<double>(d - 1) * cell_
                               : 0.0;
      return std::max(g, 0.0);
    };
    const auto gap2 = [&](int a, std::int64_t d) { return gap(a, d) * gap(a, d); };
    NearestThree squared;
    const auto visit = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      if (x < 0 || y < 0 || z < 0 || x >= kMaxCells || y >= kMaxCells || z >= kMaxCells) return;
      const std::size_t b = bucket_of(x, y, z);
      if (scanned_[b] == search_) return;
      scanned_[b] = search_;
      for (std::uint32_t k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
        const double* q = &bucketed_[3 * k];
        const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                          (p[2] - q[2]) * (p[2] - q[2]);
        if (d2 > 0) squared.offer(d2);
      }
    };
    double reach2 = 0;
    for (std::int64_t r = 0; r <= kMaxShell; ++r) {
      // The cells of shell r only (the cube's surface): an outlier's search, 16 shells deep,
      // visits 36k cells instead of walking the whole cube of each shell (167k). A cell
      // farther than the third distance found so far holds none of the three.
      for (std::int64_t dx = -r; dx <= r; ++dx) {
        const double x2 = gap2(0, dx);
        if (x2 > squared.third()) continue;
        for (std::int64_t dy = -r; dy <= r; ++dy) {
          const double xy2 = x2 + gap2(1, dy);
          if (xy2 > squared.third()) continue;
          const bool side = std::abs(dx) == r || std::abs(dy) == r;
          for (std::int64_t dz = -r; dz <= r; dz += side ? 1 : 2 * r) {
            if (xy2 + gap2(2, dz) <= squared.third()) visit(c[0] + dx, c[1] + dy, c[2] + dz);
          }
        }
      }
      // Every point outside the searched cube lies in a cell r + 1 steps away along some axis.
      double reach = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) reach = std::min({reach, gap(a, -r - 1), gap(a, r + 1)});
      reach2 = reach * reach;
      if (squared.third() <= reach2) break;
    }
    // Found exactly within reach; neighbours farther than kMaxShell cells do not count.
    const double limit = static_cast<double>(kMaxShell) * cell_;
    NearestThree out;
    for (int k = 0; k < 3; ++k) {
      if (squared.d[k] <= reach2 && squared.d[k] <= limit * limit) {
        out.d[k] = std::sqrt(squared.d[k]);
      }
    }
    return out;
  }

 private:
  std::int64_t coord(double v, int a) const {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>((v - lo_[a]) * inv_cell_), 0,
                                    kMaxCells - 1);
  }
  std::size_t bucket_of(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return static_cast<std::size_t>((cell_key(x, y, z) * 0x9E3779B97F4A7C15ull) >> bucket_shift_);
  }

  std::span<const double> xyz_;
  std::size_t n_;
  double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};
  double cell_ = 0, inv_cell_ = 0;
  int bucket_shift_ = 0;
  std::vector<std::uint32_t> bucket_start_;
  std::vector<double> bucketed_;        // xyz in bucket order
  std::vector<std::uint32_t> scanned_;  // per bucket: the last search that read it
  std::uint32_t search_ = 0;
};

}  // namespace

TileSpacing measure_tile_spacing(std::span<const double> xyz, std::span<const Index> ids,
                                 const TileBox& box, const TileBox& bounds,
                                 std::uint64_t cloud_points) {
  TileSpacing out;
  const std::size_t n = xyz.size() / 3;
  NeighbourCells cells(xyz);
  if (!cells.usable()) return out;
  const std::size_t step = (n + kSamples - 1) / kSamples;
  std::vector<NearestThree> samples;
  for (std::size_t s = 0; s < n; s += step) samples.push_back(cells.nearest_three(s));
  const std::vector<double> distances = spacing_distances(samples).distances;
  double sum = 0.0;
  for (const double d : distances) sum += d;
  out.mean = distances.empty() ? 0.0 : sum / static_cast<double>(distances.size());
  // The cloud's sample, but the points within kSeamMargin tile spacings of a face of the box
  // inside the cloud: whether a point is left out does not depend on its distance, so the
  // median is not biased. A point kept has no nearer neighbour in another tile than in its own,
  // or both are farther than the margin, far above the median.
  const std::uint64_t threshold = cloud_points <= kCloudSamples
                                      ? ~std::uint64_t{0}
                                      : (~std::uint64_t{0} / cloud_points) * kCloudSamples;
  const double margin = kSeamMargin * out.mean;
  const BorderFaces faces(box, bounds);
  for (std::size_t i = 0; i < n; ++i) {
    if (mix64(ids[i]) > threshold) continue;  // by id: the same points in any tiling
    if (faces.distance(&xyz[3 * i]) < margin) continue;
    const NearestThree near = cells.nearest_three(i);
    if (near.d[0] != std::numeric_limits<double>::infinity()) out.cloud_sample.push_back(near);
  }
  return out;
}

CloudSpacing cloud_spacing(std::span<const NearestThree> sample) {
  SpacingDistances measured = spacing_distances(sample);
  std::vector<double>& distances = measured.distances;
  if (distances.empty()) return {};
  const auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return {*middle, measured.group_distance, measured.twin_distance};
}

}  // namespace g2s::tiling
