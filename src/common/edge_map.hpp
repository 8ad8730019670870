// The Point-Edge Map of G2S (docs/algorithm.md §3): for every edge of the growing mesh, the first
// triangle on it and whether a second one has joined. An edge is kept with its smaller vertex:
// each vertex has one cache line with room for 7 edges, so a lookup reads one line; the rare
// vertex with more (and vertices past the count given) spill into an open-addressing table. An
// edge with two triangles is never given a third, so the mesh has no non-manifold edge by
// construction.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/linear_probing.hpp"
#include "g2s/types.hpp"

namespace g2s {

class EdgeMap {
 public:
  static constexpr std::uint32_t kClosed = 0x80000000u;  // value flag: edge has two triangles
  static constexpr std::uint32_t kMissing = 0xFFFFFFFFu;

  // vertex_count: vertices 0..vertex_count-1 get their own line; others are still accepted.
  explicit EdgeMap(std::size_t vertex_count = 0) { reset(vertex_count); }

  void reset(std::size_t vertex_count) {
    lines_.assign(vertex_count, Line{});
    spill_keys_.assign(16, kEmpty);
    spill_values_.assign(16, kMissing);
    spill_shift_ = 60;
    spill_size_ = 0;
    size_ = 0;
  }

  // The value for edge {u, v}: first triangle (low 31 bits) | kClosed, or kMissing.
  std::uint32_t find(Index u, Index v) const {
    const Index lo = std::min(u, v), hi = std::max(u, v);
    if (lo < lines_.size()) {
      const Line& line = lines_[lo];
      for (std::uint32_t k = 0; k < line.count; ++k) {
        if (line.other[k] == hi) return line.value[k];
      }
      if (line.count < kInline) return kMissing;
    }
    const std::uint64_t key = std::uint64_t{lo} << 32 | hi;
    for (std::size_t s = spill_slot(key);; s = (s + 1) & (spill_keys_.size() - 1)) {
      if (spill_keys_[s] == key) return spill_values_[s];
      if (spill_keys_[s] == kEmpty) return kMissing;
    }
  }

  // Starts loading the line that find(u, v) will read.
  void prefetch(Index u, Index v) const {
    const Index lo = std::min(u, v);
    if (lo < lines_.size()) __builtin_prefetch(&lines_[lo]);
  }

  // Records a triangle on edge {u, v}: first triangle, or closes it with a second.
  void add(Index u, Index v, std::uint32_t triangle) {
    const Index lo = std::min(u, v), hi = std::max(u, v);
    if (lo < lines_.size()) {
      Line& line = lines_[lo];
      for (std::uint32_t k = 0; k < line.count; ++k) {
        if (line.other[k] == hi) {
          line.value[k] |= kClosed;
          return;
        }
      }
      if (line.count < kInline) {
        line.other[line.count] = hi;
        line.value[line.count++] = triangle;
        ++size_;
        return;
      }
    }
    if ((spill_size_ + 1) * 2 > spill_keys_.size()) grow_spill();
    const std::uint64_t key = std::uint64_t{lo} << 32 | hi;
    std::size_t s = spill_slot(key);
    while (spill_keys_[s] != kEmpty && spill_keys_[s] != key) {
      s = (s + 1) & (spill_keys_.size() - 1);
    }
    if (spill_keys_[s] == key) {
      spill_values_[s] |= kClosed;
    } else {
      spill_keys_[s] = key;
      spill_values_[s] = triangle;
      ++spill_size_;
      ++size_;
    }
  }

  // Takes one triangle off edge {u, v}, which must be in the map: a closed edge becomes open,
  // still naming the triangle it named (which may be the one taken off: after removals only
  // whether an edge has none, one or two triangles is known); an open edge leaves the map.
  void remove(Index u, Index v) {
    const Index lo = std::min(u, v), hi = std::max(u, v);
    if (lo < lines_.size()) {
      Line& line = lines_[lo];
      for (std::uint32_t k = 0; k < line.count; ++k) {
        if (line.other[k] != hi) continue;
        if (line.value[k] & kClosed) {
          line.value[k] &= ~kClosed;
        } else {
          // A gap, not a shift: a full line stays full, so find() still goes on to the spill.
          line.other[k] = kGap;
          --size_;
        }
        return;
      }
    }
    const std::uint64_t key = std::uint64_t{lo} << 32 | hi;
    std::size_t s = spill_slot(key);
    while (spill_keys_[s] != key) s = (s + 1) & (spill_keys_.size() - 1);
    if (spill_values_[s] & kClosed) {
      spill_values_[s] &= ~kClosed;
      return;
    }
    erase_slot(spill_keys_, spill_values_, s, kEmpty,
               [this](std::uint64_t k) { return spill_slot(k); });
    --spill_size_;
    --size_;
  }

  // Calls visit(u, v) for every edge {u, v}, u < v, with one triangle: the lines in vertex
  // order (one sequential read), then the spill table.
  template <class Visit>
  void for_each_open(Visit&& visit) const {
    for (std::size_t lo = 0; lo < lines_.size(); ++lo) {
      const Line& line = lines_[lo];
      for (std::uint32_t k = 0; k < line.count; ++k) {
        if (line.other[k] != kGap && !(line.value[k] & kClosed)) {
          visit(static_cast<Index>(lo), line.other[k]);
        }
      }
    }
    for (std::size_t s = 0; s < spill_keys_.size(); ++s) {
      if (spill_keys_[s] != kEmpty && !(spill_values_[s] & kClosed)) {
        visit(static_cast<Index>(spill_keys_[s] >> 32), static_cast<Index>(spill_keys_[s]));
      }
    }
  }

  std::size_t size() const { return size_; }
  std::size_t memory_bytes() const {
    return lines_.size() * sizeof(Line) + spill_keys_.size() * 12;
  }

 private:
  static constexpr std::uint64_t kEmpty = ~0ull;
  static constexpr std::uint32_t kInline = 7;
  static constexpr Index kGap = 0xFFFFFFFFu;  // a removed edge's place in its line (no vertex)
  // A vertex's edges to larger vertices: 60 bytes, one cache line. A surface has about 3 such
  // edges per vertex, so few spill.
  struct alignas(64) Line {
    std::uint32_t other[kInline];
    std::uint32_t value[kInline];
    std::uint32_t count;
  };

  std::size_t spill_slot(std::uint64_t key) const {  // the top bits of the product mix best
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> spill_shift_);
  }

  void grow_spill() {
    std::vector<std::uint64_t> keys(spill_keys_.size() * 2, kEmpty);
    std::vector<std::uint32_t> values(spill_keys_.size() * 2, kMissing);
    keys.swap(spill_keys_);
    values.swap(spill_values_);
    --spill_shift_;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (keys[i] == kEmpty) continue;
      std::size_t s = spill_slot(keys[i]);
      while (spill_keys_[s] != kEmpty) s = (s + 1) & (spill_keys_.size() - 1);
      spill_keys_[s] = keys[i];
      spill_values_[s] = values[i];
    }
  }

  std::vector<Line> lines_;
  std::vector<std::uint64_t> spill_keys_;
  std::vector<std::uint32_t> spill_values_;
  int spill_shift_ = 0;  // 64 - log2(spill slots)
  std::size_t spill_size_ = 0;
  std::size_t size_ = 0;
};

}  // namespace g2s
