// Deletion from an open-addressing table with linear probing, shared by the flat hash maps
// (IdMap, EdgeMap's spill table): backward shift instead of tombstones, so probes stay short
// however many entries come and go.
#pragma once

#include <cstddef>
#include <vector>

namespace g2s {

// Removes the entry at `slot` from a table of keys and values (a power-of-two size; `empty`
// marks a free slot; home(key) is a key's first slot). Each later entry of the run moves into
// the gap unless its home lies cyclically after the gap, so every probe run stays unbroken.
template <class Key, class Value, class Home>
void erase_slot(std::vector<Key>& keys, std::vector<Value>& values, std::size_t slot, Key empty,
                Home&& home) {
  const std::size_t mask = keys.size() - 1;
  std::size_t gap = slot;
  for (std::size_t k = (slot + 1) & mask; keys[k] != empty; k = (k + 1) & mask) {
    if (((k - home(keys[k])) & mask) >= ((k - gap) & mask)) {
      keys[gap] = keys[k];
      values[gap] = values[k];
      gap = k;
    }
  }
  keys[gap] = empty;
}

}  // namespace g2s
