// Noise and outliers on a measured cloud (include/g2s/synth.hpp: mean_spacing, perturb_cloud),
// to repeat the paper's experiments on the Stanford Bunny (Di Angelo & Giaccari 2011, §5, Tables
// 3 and 4) with sigma in units of the cloud's own spacing, as the synthetic shapes have it.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "common/local_frame.hpp"
#include "g2s/error.hpp"
#include "g2s/surface_check.hpp"
#include "g2s/synth.hpp"
#include "grid/hash_grid.hpp"
#include "synth/counter_rng.hpp"
#include "synth/noise.hpp"

namespace g2s {
namespace {

struct Box {
  std::array<double, 3> lo{}, hi{};
};

Box bounding_box(const PointCloud& cloud) {
  Box box;
  for (int a = 0; a < 3; ++a) box.lo[a] = box.hi[a] = cloud.size() ? cloud.xyz[a] : 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = std::min(box.lo[a], cloud.xyz[3 * i + a]);
      box.hi[a] = std::max(box.hi[a], cloud.xyz[3 * i + a]);
    }
  }
  return box;
}

}  // namespace

double mean_spacing(const PointCloud& cloud) {
  if (cloud.size() > kNoIndex)
    throw Error(Exit::bad_input, "cloud has more than 4,294,967,295 points");
  // The grid works in float, in the mesher's frame around the box centre: a span beyond float
  // (a wild coordinate such as 1e300) would turn into infinities there.
  const Box box = bounding_box(cloud);
  if (const std::string why = why_beyond_float(box.lo.data(), box.hi.data()); !why.empty()) {
    throw Error(Exit::bad_input, "its spacing cannot be measured: " + why);
  }
  const HashGrid grid(LocalFrame(box.lo.data(), box.hi.data()).convert(cloud.xyz), {});
  if (grid.size() < 2)
    throw Error(Exit::bad_input, "the spacing of a cloud needs at least two distinct points");
  // Every nearest neighbour lies within the box's diagonal (plus float rounding).
  const double reach =
      2.0 * std::hypot(box.hi[0] - box.lo[0], box.hi[1] - box.lo[1], box.hi[2] - box.lo[2]);
  std::vector<double> distance(grid.size());
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, grid.size(), 4096),
                    [&](const tbb::blocked_range<std::uint32_t>& range) {
                      for (std::uint32_t i = range.begin(); i < range.end(); ++i) {
                        const std::uint32_t j =
                            grid.nearest(i, reach, [](std::uint32_t) { return true; });
                        distance[i] = norm(grid.position(i) - grid.position(j));
                      }
                    });
  // Summed in one fixed order, so the result does not depend on the thread count.
  return std::accumulate(distance.begin(), distance.end(), 0.0) /
         static_cast<double>(distance.size());
}

PointCloud perturb_cloud(const PointCloud& cloud, const PerturbOptions& options,
                         PerturbReport* report) {
  synth::check_noise_and_outliers("perturbed cloud", options.noise, options.outliers);
  const double spacing = mean_spacing(cloud);
  const double sigma = options.noise * spacing;
  const Box box = bounding_box(cloud);
  const std::uint64_t n = cloud.size();
  const auto outliers =
      static_cast<std::uint64_t>(std::llround(options.outliers * static_cast<double>(n)));
  PointCloud out;
  out.xyz.resize(3 * (n + outliers));
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, n + outliers, 16384),
                    [&](const tbb::blocked_range<std::uint64_t>& range) {
                      for (std::uint64_t i = range.begin(); i < range.end(); ++i) {
                        synth::CounterRng rng(options.seed, i);
                        double* p = &out.xyz[3 * i];
                        if (i < n) {
                          std::copy_n(&cloud.xyz[3 * i], 3, p);
                          if (sigma > 0.0) synth::add_gaussian_noise(rng, sigma, p);
                        } else {
                          synth::uniform_in_box(rng, box.lo, box.hi, p);
                        }
                      }
                    });
  if (report) *report = {spacing, sigma, outliers};
  return out;
}

}  // namespace g2s
