// The adaptive split of the tile store (docs/tile-store.md, "Adaptive
// split"): a k-d tree over the cloud's bounding box whose leaves are the tiles. A leaf holding
// too many points is cut across the axis whose cut has the fewest points near it (a seam's
// cost; among the axes along which the points reach nearly as far as along the widest), at the
// box's midpoint when that leaves each side at least 1/8 of its points (compact tiles, closing
// in on dense regions), else at a quantile of a sample of its points (the median when it needs two
// tiles, k/2 of k when it needs k, so tiles come out nearly full). Empty space costs nothing. The
// sample is a deterministic hash of the points' global ids, so the tiles do not depend on chunking,
// threads or timing.
#pragma once

#include <cstdint>
#include <vector>

#include "g2s/tile_store.hpp"

namespace g2s::tiling {

// Points offered while streaming are kept when a hash of their id is below a threshold; the
// threshold halves (dropping the kept points above it) whenever more than 2 * target are held.
// So at most 2 * target points are held, and which ones only depends on the ids offered.
class PointSample {
 public:
  // Room for the most it holds, reserved at once: grown by doubling, the copies were a fifth of
  // tiling a 200k-point cloud (the pages are only touched as points arrive).
  explicit PointSample(std::size_t target) : target_(target) {
    xyz_.reserve(3 * (2 * target + 1));
    hashes_.reserve(2 * target + 1);
  }

  void add(const double* p, std::uint64_t id) {
    const std::uint64_t h = hash(id);
    if (h >= threshold_) return;
    xyz_.insert(xyz_.end(), p, p + 3);
    hashes_.push_back(h);
    if (hashes_.size() > 2 * target_) shrink();
  }
  // Holds p whatever its hash, through every later shrink: the points that set the bounds, so
  // that a stray point far from the rest is seen by the split (kStrayGap) even where the sample
  // would miss it. Only for a sample that does not hold every point (which has them already).
  void add_always(const double* p) {
    xyz_.insert(xyz_.end(), p, p + 3);
    hashes_.push_back(0);
  }
  // True while every point offered is held (the threshold was never lowered).
  bool holds_every_point() const { return threshold_ == ~std::uint64_t{0}; }
  std::size_t size() const { return hashes_.size(); }
  const double* point(std::size_t i) const { return xyz_.data() + 3 * i; }

 private:
  static std::uint64_t hash(std::uint64_t id) {  // splitmix64's finaliser
    id += 0x9E3779B97F4A7C15ull;
    id = (id ^ (id >> 30)) * 0xBF58476D1CE4E5B9ull;
    id = (id ^ (id >> 27)) * 0x94D049BB133111EBull;
    return id ^ (id >> 31);
  }
  void shrink();

  std::size_t target_;
  std::uint64_t threshold_ = ~std::uint64_t{0};
  std::vector<double> xyz_;
  std::vector<std::uint64_t> hashes_;
};

// The last tile of the sweep is split down to this share of the tile budget (TileTree::taper).
constexpr double kLastTileShare = 0.25;

// A k-d tree as flat arrays of nodes; node 0 is the root (the cloud's bounding box). A point p
// goes to the right child when p[axis] >= split, so a leaf owns lo <= p < hi, and the leaves
// on the cloud's upper faces own the points lying on them.
class TileTree {
 public:
  explicit TileTree(const TileBox& bounds) { nodes_.push_back(Node{bounds}); }

  std::uint32_t leaf_of(const double* p) const {
    std::uint32_t n = 0;
    while (nodes_[n].axis >= 0) {
      const Node& node = nodes_[n];
      n = p[node.axis] < node.split ? node.left : node.right;
    }
    return n;
  }
  std::size_t node_count() const { return nodes_.size(); }
  bool is_leaf(std::uint32_t node) const { return nodes_[node].axis < 0; }
  const TileBox& box(std::uint32_t node) const { return nodes_[node].box; }

  // Splits leaf `node` by the points of `sample` (all in that leaf), each standing for `weight`
  // points, until no new leaf is estimated above `target` points or a leaf's sample points all
  // coincide. Returns whether the leaf was split.
  bool split(std::uint32_t node, const PointSample& sample, double weight, double target);

  // The leaves in sweep order: by their boxes' lower corner along the cloud's longest axis,
  // then the others (longest first). The tile order: the stitcher sweeps the tiles in it, so
  // what it holds is the band along the sweep front, not the interfaces a depth-first order
  // leaves open at every level of the tree (measured: 36% less peak memory on 40M points).
  std::vector<std::uint32_t> leaves() const;

  // With more than one leaf: splits the last leaf of the sweep in two, and again the leaf then
  // last, while it is estimated above `smallest` points (`sample`: points of the whole tree, each
  // standing for `weight`). Tiles grow in parallel in sweep order and the last one started is grown
  // alone at the end: a small last tile keeps every thread busy until the end (measured on the
  // alpine photogrammetry: its last tile grew alone for 2.6 s of a 20 s run on 2 threads).
  void taper(const PointSample& sample, double weight, double smallest);

 private:
  struct Node {
    TileBox box;
    int axis = -1;  // -1 for a leaf
    double split = 0.0;
    std::uint32_t left = 0;
    std::uint32_t right = 0;
  };
  void split_range(std::uint32_t node, const PointSample& sample, std::uint32_t* begin,
                   std::uint32_t* end, double weight, double target);

  std::vector<Node> nodes_;
};

}  // namespace g2s::tiling
