// A bounding-box tree for nearest-item queries (the point-to-mesh distances of compute_stats):
// items (points or triangles) are split at the median of their centres along the widest axis
// until at most kLeafSize remain; every node keeps the box of its items, rounded outwards to
// float. A query walks the tree nearest box first and skips every box farther than the best
// item found so far, so it is exact whatever the items' sizes and however far the query point
// lies from them. Built once, serially (deterministic); queried from any number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

#include "common/sample_spacing.hpp"

namespace g2s::stats {

class BoxTree {
 public:
  struct Box {
    double lo[3], hi[3];
  };

  // box(i) gives item i's box, for i in [0, count).
  template <typename BoxOf>
  BoxTree(std::size_t count, BoxOf&& box_of) : order_(count) {
    std::iota(order_.begin(), order_.end(), std::uint32_t{0});
    if (count == 0) return;
    std::vector<Box> boxes(count);
    for (std::size_t i = 0; i < count; ++i) boxes[i] = box_of(i);
    nodes_.reserve(2 * (count / kLeafSize + 1));
    build(boxes, 0, count);
  }

  // The smallest distance(item) over all items, and the item; distance(item) must be at least
  // the distance from p to the item's box. Items with distance < 0 are skipped.
  template <typename Distance>
  double nearest(const double p[3], Distance&& distance, std::uint32_t* best_item = nullptr) const {
    double best = std::numeric_limits<double>::infinity();
    walk_nearest_first(p, best, [&](std::uint32_t item) {
      const double d = distance(item);
      if (d >= 0 && d < best) {
        best = d;
        if (best_item != nullptr) *best_item = item;
      }
    });
    return best;
  }

  // The three smallest distance(item) over all items (infinity where fewer), with the same
  // contract on distance as nearest().
  template <typename Distance>
  NearestThree nearest_three(const double p[3], Distance&& distance) const {
    NearestThree out;
    walk_nearest_first(p, out.d[2], [&](std::uint32_t item) {
      const double d = distance(item);
      if (d >= 0) out.offer(d);
    });
    return out;
  }

  // Calls visit(item) for the items whose boxes lie within `radius` of p (a superset of the
  // items within radius: the caller measures them).
  template <typename Visit>
  void for_each_near(const double p[3], double radius, Visit&& visit) const {
    const double beyond = std::nextafter(radius, std::numeric_limits<double>::infinity());
    walk_nearest_first(p, beyond, visit);
  }

 private:
  // Visits the leaves' items nearest box first, skipping every box at least `bound` away; visit
  // may lower bound as it finds items.
  template <typename Visit>
  void walk_nearest_first(const double p[3], const double& bound, Visit&& visit) const {
    if (nodes_.empty()) return;
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (box_distance(node, p) >= bound) continue;
      if (node.count > 0) {
        for (std::uint32_t i = node.first; i < node.first + node.count; ++i) visit(order_[i]);
        continue;
      }
      const std::uint32_t left = static_cast<std::uint32_t>(&node - nodes_.data()) + 1;
      const std::uint32_t right = node.first;
      const bool left_first = box_distance(nodes_[left], p) <= box_distance(nodes_[right], p);
      stack[top++] = left_first ? right : left;  // the nearer child is popped first
      stack[top++] = left_first ? left : right;
    }
  }

  static constexpr std::uint32_t kLeafSize = 4;
  struct Node {
    float lo[3], hi[3];
    std::uint32_t first;  // a leaf's first item in order_; an inner node's right child
    std::uint32_t count;  // items of a leaf; 0 for an inner node (its left child follows it)
  };

  static double box_distance(const Node& node, const double p[3]) {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double below = static_cast<double>(node.lo[k]) - p[k];
      const double above = p[k] - static_cast<double>(node.hi[k]);
      const double d = std::max({below, above, 0.0});
      d2 += d * d;
    }
    // Rounded down a little so that the pruning test never skips an item at the same distance.
    return std::sqrt(d2) * (1.0 - 1e-12);
  }

  static float down(double d) {
    const auto f = static_cast<float>(d);
    return static_cast<double>(f) > d ? std::nextafter(f, -std::numeric_limits<float>::infinity())
                                      : f;
  }
  static float up(double d) {
    const auto f = static_cast<float>(d);
    return static_cast<double>(f) < d ? std::nextafter(f, std::numeric_limits<float>::infinity())
                                      : f;
  }

  // Builds the node of order_[begin, end) at the end of nodes_; the depth stays below 64 because
  // every split halves the range.
  std::uint32_t build(const std::vector<Box>& boxes, std::size_t begin, std::size_t end) {
    const auto id = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    double lo[3], hi[3], centre_lo[3], centre_hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = centre_lo[k] = std::numeric_limits<double>::infinity();
      hi[k] = centre_hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (std::size_t i = begin; i < end; ++i) {
      const Box& b = boxes[order_[i]];
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], b.lo[k]);
        hi[k] = std::max(hi[k], b.hi[k]);
        const double centre = 0.5 * (b.lo[k] + b.hi[k]);
        centre_lo[k] = std::min(centre_lo[k], centre);
        centre_hi[k] = std::max(centre_hi[k], centre);
      }
    }
    for (int k = 0; k < 3; ++k) {
      nodes_[id].lo[k] = down(lo[k]);
      nodes_[id].hi[k] = up(hi[k]);
    }
    if (end - begin <= kLeafSize) {
      nodes_[id].first = static_cast<std::uint32_t>(begin);
      nodes_[id].count = static_cast<std::uint32_t>(end - begin);
      return id;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k) {
      if (centre_hi[k] - centre_lo[k] > centre_hi[axis] - centre_lo[axis]) axis = k;
    }
    const std::size_t middle = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + static_cast<std::ptrdiff_t>(begin),
                     order_.begin() + static_cast<std::ptrdiff_t>(middle),
                     order_.begin() + static_cast<std::ptrdiff_t>(end),
                     [&](std::uint32_t a, std::uint32_t b) {
                       const double ca = boxes[a].lo[axis] + boxes[a].hi[axis];
                       const double cb = boxes[b].lo[axis] + boxes[b].hi[axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    build(boxes, begin, middle);
    const std::uint32_t right = build(boxes, middle, end);
    nodes_[id].first = right;
    nodes_[id].count = 0;
    return id;
  }

  std::vector<std::uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace g2s::stats
