// Wall seconds since a point on the steady clock: the timings MeshReport and the stitcher report
// (grid, growth, surface finishing, clean-up, stitching).
#pragma once

#include <chrono>

namespace g2s {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace g2s
