// The sampling spacing from the distances of sampled points to their three nearest neighbours,
// one rule for the tile store, the grid and g2s stats.
//
// The spacing is normally the median distance to the nearest neighbour. On an evenly sampled
// surface the third-nearest neighbour is at most about twice as far (the same on a square grid,
// twice along a line, 1.96 times by the medians of a random sample in the plane, 1.56 in a
// volume). A cloud whose points mostly come with a near-copy (twins: the same surface scanned
// twice and merged, fused depth maps) has its nearest-neighbour distances collapse to the
// copies' offsets, and a spacing measured there would shrink every search ball to nothing. So
// when the median nearest distance is below a quarter of the median third-nearest one, a
// sample's distance is taken to its nearest neighbour beyond that quarter, past its twins (up
// to two copies of each point). Clouds where this rule does not fire get exactly the
// nearest-neighbour distances, in their order.
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

// The nearest distance is below this fraction of the third-nearest one (by their medians) only
// in a cloud of twins.
inline constexpr double kTwinRatio = 0.25;

struct SpacingDistances {
  std::vector<double> distances;  // one per sample used, in the samples' order
  double twin_distance = 0;       // in a cloud of twins, the distance below which points are
                                  // near-copies of each other; 0 otherwise
};

// Inputs: the sampled points' three nearest distances; samples without a finite nearest distance
// (outliers) are skipped. Output: each other sample's spacing distance, in their order: its
// nearest distance, or, in a cloud of twins, its nearest beyond the twin distance (kTwinRatio
// times the median third-nearest distance; samples with none left out).
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
  const double beyond = kTwinRatio * median(third);
  if (beyond == std::numeric_limits<double>::infinity() || !(median(nearest) < beyond)) {
    return out;
  }
  out.twin_distance = beyond;
  nearest.clear();
  for (const NearestThree& s : samples) {
    const auto* d = std::find_if(s.d.begin(), s.d.end(), [&](double x) { return x > beyond; });
    if (d != s.d.end() && *d != std::numeric_limits<double>::infinity()) nearest.push_back(*d);
  }
  return out;
}

}  // namespace g2s
