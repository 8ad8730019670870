// Adaptive k-d split (see tile_split.hpp): median cuts on a deterministic sample.
#include "tiling/tile_split.hpp"

#include <algorithm>
#include <array>
#include <numeric>

namespace g2s::tiling {

void PointSample::shrink() {
  while (hashes_.size() > 2 * target_) {
    threshold_ /= 2;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < hashes_.size(); ++i) {
      if (hashes_[i] >= threshold_) continue;
      std::copy_n(xyz_.begin() + 3 * i, 3, xyz_.begin() + 3 * kept);
      hashes_[kept] = hashes_[i];
      ++kept;
    }
    xyz_.resize(3 * kept);
    hashes_.resize(kept);
  }
}

bool TileTree::split(std::uint32_t node, const PointSample& sample, double weight, double target) {
  std::vector<std::uint32_t> members(sample.size());
  std::iota(members.begin(), members.end(), 0u);
  split_range(node, sample, members.data(), members.data() + members.size(), weight, target);
  return !is_leaf(node);
}

void TileTree::split_range(std::uint32_t node, const PointSample& sample, std::uint32_t* begin,
                           std::uint32_t* end, double weight, double target) {
  if (static_cast<double>(end - begin) * weight <= target) return;
  const TileBox box = nodes_[node].box;  // a copy: nodes_ grows below
  std::array<int, 3> axes = {0, 1, 2};
  std::stable_sort(axes.begin(), axes.end(),
                   [&](int a, int b) { return box.hi[a] - box.lo[a] > box.hi[b] - box.lo[b]; });
  for (const int axis : axes) {
    auto coord = [&](std::uint32_t i) { return sample.point(i)[axis]; };
    auto by_coord = [&](std::uint32_t i, std::uint32_t j) { return coord(i) < coord(j); };
    std::uint32_t* middle = begin + (end - begin) / 2;
    std::nth_element(begin, middle, end, by_coord);
    double cut = coord(*middle);
    const double lowest = coord(*std::min_element(begin, end, by_coord));
    if (cut == lowest) {
      // More than half the points share the lowest coordinate: cut just above them.
      bool found = false;
      for (const std::uint32_t* i = begin; i != end; ++i) {
        if (coord(*i) > lowest && (!found || coord(*i) < cut)) {
          cut = coord(*i);
          found = true;
        }
      }
      if (!found) continue;  // all on one plane across this axis
    }
    std::uint32_t* mid =
        std::partition(begin, end, [&](std::uint32_t i) { return coord(i) < cut; });
    Node lower{box};
    Node upper{box};
    lower.box.hi[axis] = cut;
    upper.box.lo[axis] = cut;
    const auto left = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back(lower);
    nodes_.push_back(upper);
    nodes_[node].axis = axis;
    nodes_[node].split = cut;
    nodes_[node].left = left;
    nodes_[node].right = left + 1;
    split_range(left, sample, begin, mid, weight, target);
    split_range(left + 1, sample, mid, end, weight, target);
    return;
  }
}

std::vector<std::uint32_t> TileTree::leaves() const {
  std::vector<std::uint32_t> out;
  std::vector<std::uint32_t> stack = {0};
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    if (is_leaf(n)) {
      out.push_back(n);
    } else {
      stack.push_back(nodes_[n].right);
      stack.push_back(nodes_[n].left);
    }
  }
  return out;
}

}  // namespace g2s::tiling
