// The sampling spacing from the distances of sampled points to their three nearest neighbours,
// one rule for the tile store, the grid and g2s stats.
//
// The spacing is normally the median distance to the nearest neighbour. On an evenly sampled
// surface the third-nearest neighbour is about twice as far or less (the same on a square grid,
// twice along a line, 1.96 times by the medians of a random sample in the plane, 1.56 in a
// volume; 1.1 to 1.8 on the shared scans and the synthetic shapes). Where points come in groups
// closer than the sampling, the nearest distance measures the groups, not the sampling: LiDAR
// returns in pairs (2.8 and 3.5 times, on two of the shared LAS files), or twins (the same
// surface scanned twice and merged, fused depth maps: most points with a near-copy), where a
// spacing measured from the copies' offsets would shrink every search ball to nothing. So when
// the median nearest distance is below kTwinRatio of the median third-nearest one, a sample's
// distance is taken to its nearest neighbour beyond that fraction (past up to two other points
// of its group). Below kMergeRatio, the copies are tight enough to block the growth (a copy
// inside its twin's empty ball), and points within kMergeReach of the median third-nearest
// distance are merged (twin_distance). Clouds where the rule does not fire get exactly the
// nearest-neighbour distances, in order.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

namespace g2s {

// The three smallest distances offered, in increasing order (infinity where fewer).
struct NearestThree {
  std::array<double, 3> d{std::numeric_limits<double>::infinity(),
                          std::numeric_limits<double>::infinity(),
                          std::numeric_limits<double>::infinity()};

  void offer(double distance) {
    if (!(distance < d[2])) return;
    d[2] = distance;
    if (d[2] < d[1]) std::swap(d[1], d[2]);
    if (d[1] < d[0]) std::swap(d[0], d[1]);
  }
  double third() const { return d[2]; }
};

// Half of a random sample's 0.51 (the least even sampling of a surface), below the paired LiDAR
// files' 0.28 and 0.36. Measured past their pairs, those mesh better on their own (4_6_crop:
// coverage 97.6% -> 99.2%) but their tiles then reached farther than one tile does (3.8% fewer
// boundary edges), so they are left as they are.
inline constexpr double kTwinRatio = 0.25;
// Copies this tight are merged, within twice that reach.
inline constexpr double kMergeRatio = 0.125;
inline constexpr double kMergeReach = 0.25;

struct SpacingDistances {
  std::vector<double> distances;  // one per sample used, in the samples' order
  double group_distance = 0;      // where points come in groups, the distance the samples'
                                  // distances are taken beyond (kTwinRatio times the median
                                  // third-nearest distance); 0 otherwise
  double twin_distance = 0;       // where twins are merged, the distance below which points are
                                  // near-copies of each other (kMergeReach times the median
                                  // third-nearest distance); 0 otherwise
};

// A sample's spacing distance: its nearest beyond group_distance (0: its nearest), or infinity
// when none of its three is.
inline double distance_beyond(const NearestThree& s, double group_distance) {
  for (const double d : s.d) {
    if (d > group_distance) return d;
  }
  return std::numeric_limits<double>::infinity();
}

// Inputs: the sampled points' three nearest distances; samples without a finite nearest distance
// (outliers) are skipped. Output: each other sample's spacing distance, in their order: its
// nearest distance, or, where points come in groups, its nearest beyond the group distance
// (samples with none left out); and the group and twin distances.
inline SpacingDistances spacing_distances(std::span<const NearestThree> samples) {
  SpacingDistances out;
  std::vector<double>& nearest = out.distances;
  std::vector<double> third;
  nearest.reserve(samples.size());
  third.reserve(samples.size());
  for (const NearestThree& s : samples) {
    if (s.d[0] == std::numeric_limits<double>::infinity()) continue;
    nearest.push_back(s.d[0]);
    third.push_back(s.d[2]);
  }
  if (nearest.empty()) return out;
  const auto median = [](std::vector<double> v) {
    const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), middle, v.end());
    return *middle;
  };
  // Where most samples lack a third neighbour within reach, there is no scale to compare with.
  const double scale = median(third);
  const double middle = median(nearest);
  const double beyond = kTwinRatio * scale;
  if (scale == std::numeric_limits<double>::infinity() || !(middle < beyond)) return out;
  if (middle < kMergeRatio * scale) out.twin_distance = kMergeReach * scale;
  out.group_distance = beyond;
  nearest.clear();
  for (const NearestThree& s : samples) {
    const double d = distance_beyond(s, beyond);
    if (d != std::numeric_limits<double>::infinity()) nearest.push_back(d);
  }
  return out;
}

}  // namespace g2s
