// A flat hash map from point ids to 32-bit values: open addressing with linear probing and
// backward-shift deletion (no tombstones, so erasing keeps probes short). The stitcher keeps its
// live points in one, so its memory follows the points alive at a seam, not the cloud's size.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/linear_probing.hpp"
#include "g2s/types.hpp"

namespace g2s {

class IdMap {
 public:
  static constexpr std::uint32_t kMissing = 0xFFFFFFFFu;

  explicit IdMap(std::size_t expected = 16) { rehash(expected); }

  std::size_t size() const { return size_; }

  std::uint32_t find(Index id) const {
    for (std::size_t k = home(id);; k = (k + 1) & mask_) {
      if (keys_[k] == id) return values_[k];
      if (keys_[k] == kEmpty) return kMissing;
    }
  }

  // Starts loading the slot where a probe for id begins.
  void prefetch(Index id) const {
    const std::size_t k = home(id);
    __builtin_prefetch(&keys_[k]);
    __builtin_prefetch(&values_[k]);
  }

  // Inserts id -> value; an id already there keeps its value. Returns the value stored.
  std::uint32_t insert(Index id, std::uint32_t value) {
    if (2 * (size_ + 1) > keys_.size()) rehash(2 * keys_.size());
    for (std::size_t k = home(id);; k = (k + 1) & mask_) {
      if (keys_[k] == id) return values_[k];
      if (keys_[k] == kEmpty) {
        keys_[k] = id;
        values_[k] = value;
        ++size_;
        return value;
      }
    }
  }

  void erase(Index id) {
    std::size_t hole = home(id);
    while (keys_[hole] != id) {
      if (keys_[hole] == kEmpty) return;
      hole = (hole + 1) & mask_;
    }
    erase_slot(keys_, values_, hole, kEmpty, [this](Index key) { return home(key); });
    --size_;
  }

  void clear() {
    std::fill(keys_.begin(), keys_.end(), kEmpty);
    size_ = 0;
  }

 private:
  static constexpr Index kEmpty = kNoIndex;  // never a point id: clouds have fewer points

  std::size_t home(Index id) const {
    return static_cast<std::size_t>((std::uint64_t{id} * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  void rehash(std::size_t capacity) {
    std::size_t slots = 16;
    int bits = 4;
    while (slots < capacity) {
      slots *= 2;
      ++bits;
    }
    std::vector<Index> keys(slots, kEmpty);
    std::vector<std::uint32_t> values(slots);
    keys.swap(keys_);
    values.swap(values_);
    mask_ = slots - 1;
    shift_ = 64 - bits;
    size_ = 0;
    for (std::size_t k = 0; k < keys.size(); ++k) {
      if (keys[k] != kEmpty) insert(keys[k], values[k]);
    }
  }

  std::vector<Index> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;
};

}  // namespace g2s
