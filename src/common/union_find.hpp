// Union-find over flat arrays: plain roots with path halving, and a variant that also carries a
// parity bit on every link (the orientation groups of the grower and the stitcher: two
// triangles of one group face the same way when their parities are equal).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace g2s {

inline std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

class ParityUnionFind {
 public:
  std::uint32_t add() {
    parent_.push_back(static_cast<std::uint32_t>(parent_.size()));
    parity_.push_back(0);
    return parent_.back();
  }
  std::size_t size() const { return parent_.size(); }

  // The root of x and x's parity relative to it (path compression on the way).
  std::pair<std::uint32_t, std::uint8_t> find(std::uint32_t x) {
    std::uint8_t p = 0;
    std::uint32_t r = x;
    while (parent_[r] != r) {
      p ^= parity_[r];
      r = parent_[r];
    }
    // Second pass: point every node on the path straight at the root with its full parity.
    std::uint8_t rest = p;
    while (parent_[x] != x) {
      const std::uint32_t next = parent_[x];
      const std::uint8_t own = parity_[x];
      parent_[x] = r;
      parity_[x] = rest;
      rest ^= own;
      x = next;
    }
    return {r, p};
  }

  // Records parity(x) ^ parity(y) == relation; false (and nothing changes) if that contradicts
  // what is already known.
  bool unite(std::uint32_t x, std::uint32_t y, std::uint8_t relation) {
    const auto [rx, px] = find(x);
    const auto [ry, py] = find(y);
    if (rx == ry) return (px ^ py) == relation;
    // Smaller root wins, so the result does not depend on the order links arrive in.
    const auto [keep, drop] = rx < ry ? std::pair{rx, ry} : std::pair{ry, rx};
    parent_[drop] = keep;
    parity_[drop] = static_cast<std::uint8_t>(px ^ py ^ relation);
    return true;
  }

 private:
  std::vector<std::uint32_t> parent_;
  std::vector<std::uint8_t> parity_;
};

}  // namespace g2s
