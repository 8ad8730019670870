// Adaptive k-d split (see tile_split.hpp): each cut across the axis with the fewest points near
// it, at the midpoint or a quantile, on a deterministic sample.
#include "tiling/tile_split.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace g2s::tiling {
namespace {

// A midpoint cut must leave each side this fraction (1/8) of the points, else the cut is at a
// quantile. Lower fractions isolate dense clusters in smaller boxes but leave more, emptier
// tiles (on the bun000 scan at 1000 points per tile: 1/4 gives 52 tiles, 1/8 gives 60, any
// non-empty side 68, for 41 full ones).
constexpr std::ptrdiff_t kMinShare = 8;
// The width on each side of a cut within which its points are counted, as a share of the widest
// extent of the node's points: the halo's (8 spacings) beside a square patch of surface of about
// 64k points, the tiles of a tight --memory; wider beside larger nodes, which only ranks the
// axes the same way.
constexpr double kSeamWidthShare = 1.0 / 32;

// The cut of a node across `axis`: the box's midpoint when it leaves each side at least
// 1/kMinShare of the points (compact tiles, fewer border points to exchange, closing in on dense
// regions), else the quantile lower_share. False when every point lies on one plane across it.
bool cut_along(const PointSample& sample, std::uint32_t* begin, std::uint32_t* end,
               const TileBox& box, int axis, double lower_share, double& cut) {
  auto coord = [&](std::uint32_t i) { return sample.point(i)[axis]; };
  auto by_coord = [&](std::uint32_t i, std::uint32_t j) { return coord(i) < coord(j); };
  cut = 0.5 * (box.lo[axis] + box.hi[axis]);
  const auto below = std::count_if(begin, end, [&](std::uint32_t i) { return coord(i) < cut; });
  if (kMinShare * below < end - begin || kMinShare * below > (kMinShare - 1) * (end - begin)) {
    // Otherwise the quantile, so that an uneven node still splits into nearly full tiles.
    std::uint32_t* middle =
        begin + static_cast<std::ptrdiff_t>(static_cast<double>(end - begin) * lower_share);
    std::nth_element(begin, middle, end, by_coord);
    cut = coord(*middle);
    const double lowest = coord(*std::min_element(begin, end, by_coord));
    if (cut == lowest) {
      // The points below the cut share the lowest coordinate: cut just above them.
      bool found = false;
      for (const std::uint32_t* i = begin; i != end; ++i) {
        if (coord(*i) > lowest && (!found || coord(*i) < cut)) {
          cut = coord(*i);
          found = true;
        }
      }
      if (!found) return false;  // all on one plane across this axis
    }
    if (cut == box.hi[axis]) {
      // Many points lie on the box's upper face, which is the cloud's: cutting there would
      // leave a flat tile on the cloud's face, a neighbour that the face rules out of the
      // lower tile's border. Cut halfway below them instead.
      double next_lower = lowest;
      for (const std::uint32_t* i = begin; i != end; ++i) {
        if (coord(*i) < cut) next_lower = std::max(next_lower, coord(*i));
      }
      const double halfway = 0.5 * (next_lower + cut);
      if (next_lower < halfway && halfway < cut) cut = halfway;
    }
  }
  return true;
}

// The cut through a stray gap (kStrayGap, g2s/tile_store.hpp) of the points [begin, end), whose
// extent is [lo, hi], if any: along the axis of the widest such gap, halfway across it. One pass
// an axis: both groups lie within 1/kStrayGap of the extent from its ends.
bool stray_cut(const PointSample& sample, const std::uint32_t* begin, const std::uint32_t* end,
               const double lo[3], const double hi[3], int& axis, double& cut) {
  double widest_gap = 0;
  for (int a = 0; a < 3; ++a) {
    const double band = (hi[a] - lo[a]) / kStrayGap;
    if (!(band > 0)) continue;
    double low_top = lo[a], high_bottom = hi[a];  // the low group's top, the high group's bottom
    bool two_groups = true;
    for (const std::uint32_t* i = begin; i != end && two_groups; ++i) {
      const double c = sample.point(*i)[a];
      if (c - lo[a] <= band) {
        low_top = std::max(low_top, c);
      } else if (hi[a] - c <= band) {
        high_bottom = std::min(high_bottom, c);
      } else {
        two_groups = false;
      }
    }
    // One group must have a width: a few lone points (a tetrahedron's corners) are no scan.
    const double group = std::max(low_top - lo[a], hi[a] - high_bottom);
    const double gap = high_bottom - low_top;
    if (!two_groups || !(group > 0) || !(gap > kStrayGap * group)) continue;
    if (gap > widest_gap) {
      widest_gap = gap;
      axis = a;
      cut = 0.5 * (low_top + high_bottom);
    }
  }
  return widest_gap > 0;
}

}  // namespace

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
  const double estimate = static_cast<double>(end - begin) * weight;
  if (end - begin < 2) return;  // one point cannot be split
  // The extent of the node's points along each axis.
  double lo[3], hi[3], extent[3];
  for (int a = 0; a < 3; ++a) lo[a] = hi[a] = sample.point(*begin)[a];
  for (const std::uint32_t* i = begin; i != end; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], sample.point(*i)[a]);
      hi[a] = std::max(hi[a], sample.point(*i)[a]);
    }
  }
  for (int a = 0; a < 3; ++a) extent[a] = hi[a] - lo[a];
  int stray_axis = 0;
  double stray_at = 0;
  const bool stray = stray_cut(sample, begin, end, lo, hi, stray_axis, stray_at);
  if (!stray && estimate <= target) return;
  // A quantile cut gives the lower side floor(k/2) of the k tiles the points need, so that
  // tiles come out nearly full rather than between half and all of the budget.
  const double pieces = std::ceil(estimate / target);
  const double lower_share = std::floor(pieces / 2) / pieces;
  const TileBox box = nodes_[node].box;  // a copy: nodes_ grows below
  std::array<int, 3> axes = {0, 1, 2};
  std::stable_sort(axes.begin(), axes.end(),
                   [&](int a, int b) { return box.hi[a] - box.lo[a] > box.hi[b] - box.lo[b]; });
  const double widest = *std::max_element(std::begin(extent), std::end(extent));
  // Each axis's cut, then the one with the fewest points near it among the axes along which the
  // points reach at least 2/3 as far as along the widest (so that tiles stay compact and a
  // dense cluster still gets cut down to tiles of its own): a seam costs by the points within
  // a halo's width of it, and a plane meeting the surface at a glancing angle (a horizontal cut
  // through sloping terrain) has many more of them than its length says. Ties keep the longest
  // side of the box.
  const double near = widest * kSeamWidthShare;
  int best_axis = stray ? stray_axis : -1;
  double best_cut = stray_at;
  std::pair<bool, std::ptrdiff_t> best_score;  // (too narrow, points near the cut)
  for (const int axis : axes) {
    if (stray) break;
    double cut = 0;
    if (!cut_along(sample, begin, end, box, axis, lower_share, cut)) continue;
    const auto close = std::count_if(
        begin, end, [&](std::uint32_t i) { return std::abs(sample.point(i)[axis] - cut) <= near; });
    const std::pair<bool, std::ptrdiff_t> score{3 * extent[axis] < 2 * widest, close};
    if (best_axis < 0 || score < best_score) {
      best_axis = axis;
      best_cut = cut;
      best_score = score;
    }
  }
  if (best_axis < 0) return;  // all points coincide
  std::uint32_t* mid = std::partition(
      begin, end, [&](std::uint32_t i) { return sample.point(i)[best_axis] < best_cut; });
  Node lower{box};
  Node upper{box};
  lower.box.hi[best_axis] = best_cut;
  upper.box.lo[best_axis] = best_cut;
  const auto left = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back(lower);
  nodes_.push_back(upper);
  nodes_[node].axis = best_axis;
  nodes_[node].split = best_cut;
  nodes_[node].left = left;
  nodes_[node].right = left + 1;
  split_range(left, sample, begin, mid, weight, target);
  split_range(left + 1, sample, mid, end, weight, target);
}

void TileTree::taper(const PointSample& sample, double weight, double smallest) {
  std::vector<std::uint32_t> members(sample.size());
  std::iota(members.begin(), members.end(), 0u);
  for (;;) {
    const std::vector<std::uint32_t> order = leaves();
    if (order.size() < 2) return;  // a cloud that fits in one tile stays one
    const std::uint32_t last = order.back();
    // The sweep orders leaves by their lower corners, so the children of the last leaf come
    // after every other leaf: the new last leaf's points are among the old one's.
    std::erase_if(members, [&](std::uint32_t i) { return leaf_of(sample.point(i)) != last; });
    const double estimate = static_cast<double>(members.size()) * weight;
    if (!(estimate > smallest)) return;
    // One cut: every cut leaves each side at most 7/8 of the points.
    split_range(last, sample, members.data(), members.data() + members.size(), weight,
                estimate * (kMinShare - 1) / kMinShare);
    if (is_leaf(last)) return;  // its points all coincide
  }
}

std::vector<std::uint32_t> TileTree::leaves() const {
  std::vector<std::uint32_t> out;
  for (std::uint32_t n = 0; n < nodes_.size(); ++n) {
    if (is_leaf(n)) out.push_back(n);
  }
  const TileBox& all = nodes_[0].box;
  std::array<int, 3> axes = {0, 1, 2};
  std::stable_sort(axes.begin(), axes.end(),
                   [&](int a, int b) { return all.hi[a] - all.lo[a] > all.hi[b] - all.lo[b]; });
  // Leaves do not overlap, so no two share a lower corner: the order is total.
  std::sort(out.begin(), out.end(), [&](std::uint32_t a, std::uint32_t b) {
    const TileBox &p = nodes_[a].box, &q = nodes_[b].box;
    for (const int axis : axes) {
      if (p.lo[axis] != q.lo[axis]) return p.lo[axis] < q.lo[axis];
    }
    return a < b;
  });
  return out;
}

}  // namespace g2s::tiling
