// Union-find root with path halving, over a flat parent array (parent[x] == x at a root).
#pragma once

#include <cstdint>
#include <vector>

namespace g2s {

inline std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace g2s
