// Orientation of the grown components. Growing keeps neighbouring triangles consistent, but
// each component starts from a seed of arbitrary orientation; here every component is flipped as
// a whole so that closed surfaces face outward. Components are found by a union-find over
// vertices: after non-manifold removal every vertex has one fan, so triangles sharing a vertex
// are joined along edges too.
#include <cmath>
#include <numeric>

#include "cleanup/cleanup.hpp"
#include "common/edge_map.hpp"
#include "common/union_find.hpp"

namespace g2s {
std::vector<std::array<Index, 2>> open_edges(const std::vector<Triangle>& triangles,
                                             std::size_t vertex_count) {
  EdgeMap edges(vertex_count);
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) edges.add(triangles[t][k], triangles[t][(k + 1) % 3], t);
  }
  std::vector<std::array<Index, 2>> open;
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      if (!(edges.find(t[k], t[(k + 1) % 3]) & EdgeMap::kClosed))
        open.push_back({t[k], t[(k + 1) % 3]});
    }
  }
  return open;
}

namespace {

// open: the open edges when the caller has them (reversed with their component); null: a
// component is open when the XOR of its triangles' edge keys is not zero. With no
// non-manifold edge every inner edge is counted twice and cancels, so what is left is the XOR
// of the boundary edges' keys, zero for a closed component and (but with odds of 2^-64) not zero
// otherwise; no edge map over the whole mesh is needed.
std::uint64_t orient(std::vector<Triangle>& triangles, std::span<const Vec3f> positions,
                     std::vector<std::array<Index, 2>>* open) {
  const auto nv = static_cast<std::uint32_t>(positions.size());
  std::vector<std::uint32_t> parent(nv);
  std::iota(parent.begin(), parent.end(), 0u);
  for (const Triangle& t : triangles) {
    const std::uint32_t r = find_root(parent, t[0]);
    parent[find_root(parent, t[1])] = r;
    parent[find_root(parent, t[2])] = find_root(parent, r);
  }
  // Dense component numbers, so the sums below cost per component, not per vertex.
  std::vector<std::uint32_t> component(nv, kNoIndex);
  std::uint32_t components = 0;
  for (const Triangle& t : triangles) {
    const std::uint32_t r = find_root(parent, t[0]);
    if (component[r] == kNoIndex) component[r] = components++;
  }
  auto component_of = [&](Index v) { return component[find_root(parent, v)]; };
  struct Sum {
    Vec3 centroid{0, 0, 0};
    Vec3 normal{0, 0, 0};
    double volume = 0;
    bool open = false;
    std::uint64_t edges = 0;  // XOR of the edge keys
    double count = 0;
  };
  std::vector<Sum> sums(components);
  auto pos = [&](Index i) { return Vec3(positions[i]); };
  for (const Triangle& t : triangles) {
    Sum& s = sums[component_of(t[0])];
    for (Index v : t) s.centroid = s.centroid + pos(v);
    s.count += 3;
  }
  if (open) {
    for (const auto& e : *open) sums[component_of(e[0])].open = true;
  } else {
    for (const Triangle& t : triangles) {
      sums[component_of(t[0])].edges ^=
          edge_key(t[0], t[1]) ^ edge_key(t[1], t[2]) ^ edge_key(t[2], t[0]);
    }
    for (Sum& s : sums) s.open = s.edges != 0;
  }
  for (const Triangle& t : triangles) {
    Sum& s = sums[component_of(t[0])];
    const Vec3 o = s.centroid * (1.0 / s.count);
    const Vec3 a = pos(t[0]) - o, b = pos(t[1]) - o, c = pos(t[2]) - o;
    s.volume += dot(a, cross(b, c));
    s.normal = s.normal + cross(b - a, c - a);
  }
  std::uint64_t flipped = 0;
  std::vector<std::uint8_t> flip(components, 0);
  for (std::uint32_t k = 0; k < components; ++k) {
    const Sum& s = sums[k];
    const bool vertical = s.open && std::abs(s.normal.z) > 0.5 * norm(s.normal);
    flip[k] = vertical ? s.normal.z < 0 : s.volume < 0;
    flipped += flip[k];
  }
  for (Triangle& t : triangles) {
    if (flip[component_of(t[0])]) std::swap(t[1], t[2]);
  }
  if (open) {
    for (auto& e : *open) {
      if (flip[component_of(e[0])]) std::swap(e[0], e[1]);
    }
  }
  return flipped;
}

}  // namespace

std::uint64_t orient_components(std::vector<Triangle>& triangles,
                                std::span<const Vec3f> positions) {
  return orient(triangles, positions, nullptr);
}

std::uint64_t orient_components(std::vector<Triangle>& triangles, std::span<const Vec3f> positions,
                                std::vector<std::array<Index, 2>>& open) {
  return orient(triangles, positions, &open);
}

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
