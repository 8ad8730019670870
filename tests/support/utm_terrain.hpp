// A georeferenced test terrain: a side x side grid 0.25 m apart in UTM-sized coordinates (x about
// 500,000 m, y about 5,000,000 m, z about 300 m with a centimetre ripple), as XYZ text. The
// stray-point tests put points far from it.
#pragma once

#include <fmt/format.h>

#include <string>

namespace g2s::test_support {

inline std::string utm_terrain_xyz(int side) {
  std::string text;
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      text += fmt::format("{} {} {}\n", 500000.123 + 0.25 * i, 5000000.456 + 0.25 * j,
                          300 + 0.01 * ((i * j) % 7));
    }
  }
  return text;
}

}  // namespace g2s::test_support
