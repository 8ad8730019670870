// Counter-based random numbers for the synthetic clouds: every point owns a splitmix64 stream
// seeded by (seed, point index), so any range of points can be generated on its own, in any
// order and on any thread, and the cloud does not depend on chunking or thread count.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace g2s::synth {

// The splitmix64 finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mix.
inline std::uint64_t mix64(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

class CounterRng {
 public:
  CounterRng(std::uint64_t seed, std::uint64_t index)
      : state_(mix64(mix64(seed ^ 0x6A09E667F3BCC909ull) + index * kGolden)) {}

  std::uint64_t next() {
    state_ += kGolden;
    return mix64(state_);
  }
  // Uniform in [0, 1): 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Two independent standard normals (Box-Muller; the first uniform is in (0, 1]).
  void normal_pair(double& a, double& b) {
    const double u1 = static_cast<double>((next() >> 11) + 1) * 0x1.0p-53;
    const double u2 = uniform();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * std::numbers::pi * u2;
    a = radius * std::cos(angle);
    b = radius * std::sin(angle);
  }

 private:
  static constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ull;
  std::uint64_t state_;
};

}  // namespace g2s::synth
