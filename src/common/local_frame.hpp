// The mesher's float frame. Points are meshed in float (the hash grid and the grower store 3
// floats a point), relative to the centre of a box: a tile's, a seam's tile, or a whole cloud's.
// The offset is taken in double before rounding, so georeferenced coordinates (around 1e7) keep
// float's full precision near the centre. Every stage converts through here, so the same point
// of the same box gets the same float wherever it is meshed.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace g2s {

class LocalFrame {
 public:
  LocalFrame(const double lo[3], const double hi[3]) {
    for (int a = 0; a < 3; ++a) centre_[a] = 0.5 * (lo[a] + hi[a]);
  }
  // Appends point p (3 doubles) in the frame to `out`.
  void append(const double* p, std::vector<float>& out) const {
    for (int a = 0; a < 3; ++a) out.push_back(static_cast<float>(p[a] - centre_[a]));
  }
  // All points of xyz (3 doubles each) in the frame.
  std::vector<float> convert(std::span<const double> xyz) const {
    std::vector<float> local(xyz.size());
    for (std::size_t k = 0; k < xyz.size(); ++k) {
      local[k] = static_cast<float>(xyz[k] - centre_[k % 3]);
    }
    return local;
  }

 private:
  double centre_[3];
};

}  // namespace g2s
