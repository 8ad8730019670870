// The two perturbations of the paper's robustness experiments (Di Angelo & Giaccari 2011,
// §5, Tables 3 and 4): Gaussian noise on every coordinate and outliers uniform in a box. Shared
// by the synthetic shapes (sampler.cpp) and by measured clouds (perturb.cpp), so both draw the
// same way from a point's own counter-based stream.
#pragma once

#include <fmt/core.h>

#include <array>
#include <cmath>
#include <string_view>

#include "g2s/error.hpp"
#include "synth/counter_rng.hpp"

namespace g2s::synth {

// Far beyond any real use; keeps the outlier count exact in double arithmetic.
inline constexpr double kMaxOutliers = 100.0;

// Throws Error(usage) "<what>: ..." unless noise is finite and >= 0 and outliers in
// [0, kMaxOutliers].
inline void check_noise_and_outliers(std::string_view what, double noise, double outliers) {
  if (!std::isfinite(noise) || noise < 0.0)
    throw Error(Exit::usage, fmt::format("{}: noise must be finite and >= 0, not {}", what, noise));
  if (!std::isfinite(outliers) || outliers < 0.0 || outliers > kMaxOutliers)
    throw Error(Exit::usage, fmt::format("{}: outliers must be in [0, {}], not {}", what,
                                         kMaxOutliers, outliers));
}

// Adds sigma * N(0, 1) independently to p[0], p[1] and p[2]: four normals drawn, one unused.
inline void add_gaussian_noise(CounterRng& rng, double sigma, double p[3]) {
  double n0, n1, n2, unused;
  rng.normal_pair(n0, n1);
  rng.normal_pair(n2, unused);
  p[0] += sigma * n0;
  p[1] += sigma * n1;
  p[2] += sigma * n2;
}

// A point uniform in the axis-aligned box [lo, hi], one uniform per axis, x first.
inline void uniform_in_box(CounterRng& rng, const std::array<double, 3>& lo,
                           const std::array<double, 3>& hi, double p[3]) {
  for (int a = 0; a < 3; ++a) p[a] = lo[a] + rng.uniform() * (hi[a] - lo[a]);
}

}  // namespace g2s::synth
