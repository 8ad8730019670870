// splitmix64's finaliser: spreads every input bit over the whole word (hash tables and hashed
// grids).
#pragma once

#include <cstdint>

namespace g2s {

inline std::uint64_t mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

}  // namespace g2s
