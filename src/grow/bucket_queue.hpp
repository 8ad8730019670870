// The discrete priority queue of G2S (docs/algorithm.md §4) as a bucket queue: one FIFO per
// priority value, O(1) push and pop, no heap. Lower priority values are drained first.
#pragma once

#include <cstdint>
#include <vector>

namespace g2s {

template <class Item>
class BucketQueue {
 public:
  explicit BucketQueue(int levels) : fifos_(static_cast<std::size_t>(levels)) {}

  // priority in [0, levels).
  void push(int priority, const Item& item) {
    fifos_[static_cast<std::size_t>(priority)].items.push_back(item);
    if (priority < lowest_) lowest_ = priority;
    ++size_;
  }

  bool empty() const { return size_ == 0; }

  // The item `ahead` places behind the next one to pop, if it is in the same level (nullptr
  // otherwise): what the front will most likely process soon, for prefetching.
  const Item* peek(std::size_t ahead) const {
    for (std::size_t level = static_cast<std::size_t>(lowest_); level < fifos_.size(); ++level) {
      const Fifo& f = fifos_[level];
      if (f.head == f.items.size()) continue;
      return f.head + ahead < f.items.size() ? &f.items[f.head + ahead] : nullptr;
    }
    return nullptr;
  }

  // Pops the oldest item of the lowest non-empty level; returns that level.
  int pop(Item& out) {
    while (fifos_[static_cast<std::size_t>(lowest_)].head ==
           fifos_[static_cast<std::size_t>(lowest_)].items.size()) {
      ++lowest_;
    }
    Fifo& f = fifos_[static_cast<std::size_t>(lowest_)];
    out = f.items[f.head++];
    --size_;
    if (f.head == f.items.size()) {
      f.items.clear();
      f.head = 0;
    } else if (f.head >= 4096 && f.head * 2 >= f.items.size()) {
      f.items.erase(f.items.begin(), f.items.begin() + static_cast<std::ptrdiff_t>(f.head));
      f.head = 0;
    }
    return lowest_;
  }

 private:
  struct Fifo {
    std::vector<Item> items;
    std::size_t head = 0;
  };
  std::vector<Fifo> fifos_;
  int lowest_ = 0;
  std::size_t size_ = 0;
};

}  // namespace g2s
