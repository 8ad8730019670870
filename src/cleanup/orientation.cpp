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

std::uint64_t orient_components(std::vector<Triangle>& triangles,
                                std::span<const Vec3f> positions) {
  std::vector<std::array<Index, 2>> open = open_edges(triangles, positions.size());
  return orient_components(triangles, positions, open);
}

std::uint64_t orient_components(std::vector<Triangle>& triangles, std::span<const Vec3f> positions,
                                std::vector<std::array<Index, 2>>& open) {
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
    double count = 0;
  };
  std::vector<Sum> sums(components);
  auto pos = [&](Index i) { return Vec3(positions[i]); };
  for (const Triangle& t : triangles) {
    Sum& s = sums[component_of(t[0])];
    for (Index v : t) s.centroid = s.centroid + pos(v);
    s.count += 3;
  }
  for (const auto& e : open) sums[component_of(e[0])].open = true;
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
  for (auto& e : open) {
    if (flip[component_of(e[0])]) std::swap(e[0], e[1]);
  }
  return flipped;
}

}  // namespace g2s
