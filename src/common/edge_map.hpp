// The Point-Edge Map of G2S (ALGORITHM.md §4): for every edge of the growing mesh, the first
// triangle on it and whether a second one has joined. Open addressing on the sorted vertex pair;
// two flat arrays (keys, values), grown by doubling. An edge with two triangles is never given a
// third, so the mesh has no non-manifold edge by construction.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "g2s/types.hpp"

namespace g2s {

class EdgeMap {
 public:
  static constexpr std::uint32_t kClosed = 0x80000000u;  // value flag: edge has two triangles
  static constexpr std::uint32_t kMissing = 0xFFFFFFFFu;

  // vertex_count: vertices are 0..vertex_count-1.
  explicit EdgeMap(std::size_t vertex_count = 0) { reset(vertex_count); }

  void reset(std::size_t vertex_count) {
    std::size_t slots = 128;  // at least two regions, so region_shift_ stays below 64
    // 8 slots per vertex: a triangulated surface has about 3 edges per vertex (counted at the
    // smaller one), so the load stays near 3/8 and probe runs short.
    while (slots < vertex_count * 8) slots *= 2;
    keys_.assign(slots, kEmpty);
    values_.assign(slots, kMissing);
    mask_ = slots - 1;
    region_shift_ = 64 - std::countr_zero(slots / 64);
    size_ = 0;
  }

  // The value for edge {u, v}: first triangle (low 31 bits) | kClosed, or kMissing.
  std::uint32_t find(Index u, Index v) const {
    const std::uint64_t key = make_key(u, v);
    for (std::uint64_t s = slot_of(key);; s = (s + 1) & mask_) {
      if (keys_[s] == key) return values_[s];
      if (keys_[s] == kEmpty) return kMissing;
    }
  }

  // Records a triangle on edge {u, v}: first triangle, or closes it with a second.
  void add(Index u, Index v, std::uint32_t triangle) {
    if ((size_ + 1) * 8 > (mask_ + 1) * 5) grow();
    const std::uint64_t key = make_key(u, v);
    std::uint64_t s = slot_of(key);
    while (keys_[s] != kEmpty && keys_[s] != key) s = (s + 1) & mask_;
    if (keys_[s] == key) {
      values_[s] |= kClosed;
    } else {
      keys_[s] = key;
      values_[s] = triangle;
      ++size_;
    }
  }

  std::size_t size() const { return size_; }
  std::size_t memory_bytes() const { return keys_.size() * 12; }

 private:
  static constexpr std::uint64_t kEmpty = ~0ull;
  static std::uint64_t make_key(Index u, Index v) {
    return u < v ? std::uint64_t{u} << 32 | v : std::uint64_t{v} << 32 | u;
  }
  // An edge's probe starts in its smaller vertex's own 8 slots, inside a 64-slot region shared
  // by 8 consecutive vertices: points are in Morton order, so the edges of nearby points share
  // cache lines and a growing front touches memory locally. Regions are placed by a hash, so a
  // crowded region spills into a random one, not into its neighbours' (no long probe runs when
  // a few vertices have many edges).
  std::uint64_t slot_of(std::uint64_t key) const {
    const std::uint64_t min = key >> 32;
    const std::uint64_t region = ((min >> 3) * 0x9E3779B97F4A7C15ull) >> region_shift_;
    return (region << 6 | (min & 7) << 3 | (key & 7)) & mask_;
  }

  void grow() {
    std::vector<std::uint64_t> keys(keys_.size() * 2, kEmpty);
    std::vector<std::uint32_t> values(keys_.size() * 2, kMissing);
    keys.swap(keys_);
    values.swap(values_);
    mask_ = keys_.size() - 1;
    region_shift_ = 64 - std::countr_zero(keys_.size() / 64);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (keys[i] == kEmpty) continue;
      std::uint64_t s = slot_of(keys[i]);
      while (keys_[s] != kEmpty) s = (s + 1) & mask_;
      keys_[s] = keys[i];
      values_[s] = values[i];
    }
  }

  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> values_;
  std::uint64_t mask_ = 0;
  int region_shift_ = 63;  // 64 - log2(number of 64-slot regions)
  std::size_t size_ = 0;
};

}  // namespace g2s
