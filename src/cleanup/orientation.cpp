// Orientation of the grown components. Growing keeps neighbouring triangles consistent, but
// each component starts from seeds of arbitrary orientation. The stitcher records which
// orientation groups meet and with what parity, and each group's sums; here each component is
// made consistent by its parity and then flipped as a whole so that closed surfaces face
// outward, all without the triangles: the mesh sink, which has them by then, reverses each
// group's triangles as the flips say.
#include <cmath>

#include "cleanup/cleanup.hpp"
#include "common/union_find.hpp"

namespace g2s {
std::vector<std::uint8_t> group_flips(ParityUnionFind& groups, std::span<const GroupSums> sums,
                                      bool orient, std::uint64_t& flipped) {
  const std::size_t n = groups.size();
  // The component's sums (at its root group) with each group's sums as its parity turns them.
  std::vector<GroupSums> component(n);
  std::vector<std::uint8_t> parity(n);
  for (std::uint32_t g = 0; g < n; ++g) {
    const auto [root, p] = groups.find(g);
    parity[g] = p;
    const GroupSums& s = sums[g];
    GroupSums& c = component[root];
    const double sign = p ? -1.0 : 1.0;
    c.det += sign * s.det;
    c.normal = c.normal + s.normal * sign;
    c.centroid = c.centroid + s.centroid;
    c.corners += s.corners;
    c.edge_keys ^= s.edge_keys;
  }
  std::vector<std::uint8_t> reverse(n, 0);  // per root
  flipped = 0;
  for (std::uint32_t g = 0; g < n && orient; ++g) {
    const GroupSums& c = component[g];
    if (c.corners == 0) continue;  // not a root, or no triangle left
    const Vec3 centre = c.centroid * (1.0 / c.corners);
    const double volume = c.det - dot(centre, c.normal);
    const bool vertical = c.edge_keys != 0 && std::abs(c.normal.z) > 0.5 * norm(c.normal);
    reverse[g] = vertical ? c.normal.z < 0 : volume < 0;
    flipped += reverse[g];
  }
  std::vector<std::uint8_t> flip(n);
  for (std::uint32_t g = 0; g < n; ++g) flip[g] = parity[g] ^ reverse[groups.find(g).first];
  return flip;
}

}  // namespace g2s
