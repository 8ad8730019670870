// Orientation of the grown components. Growing keeps neighbouring triangles consistent, but
// each component starts from a seed of arbitrary orientation; here every edge-connected
// component is flipped as a whole so that closed surfaces face outward.
#include <cmath>
#include <numeric>

#include "cleanup/cleanup.hpp"
#include "common/edge_map.hpp"

namespace g2s {
namespace {

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::uint64_t orient_components(std::vector<Triangle>& triangles,
                                std::span<const Vec3f> positions) {
  const auto nt = static_cast<std::uint32_t>(triangles.size());
  std::vector<std::uint32_t> parent(nt);
  std::iota(parent.begin(), parent.end(), 0u);
  // Per triangle: edges it opened minus edges it closed; a component is closed when they cancel.
  std::vector<std::int64_t> open_balance(nt, 0);
  EdgeMap edges(positions.size());
  for (std::uint32_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 3; ++k) {
      const Index u = triangles[t][k], v = triangles[t][(k + 1) % 3];
      const std::uint32_t other = edges.find(u, v);
      edges.add(u, v, t);
      if (other == EdgeMap::kMissing) {
        ++open_balance[t];
      } else {
        --open_balance[t];
        parent[find_root(parent, t)] = find_root(parent, other & ~EdgeMap::kClosed);
      }
    }
  }
  struct Sum {
    Vec3 centroid{0, 0, 0};
    Vec3 normal{0, 0, 0};
    double volume = 0;
    std::int64_t open = 0;
    double count = 0;
  };
  // Dense component numbers, so the sums below cost per component, not per triangle.
  std::vector<std::uint32_t> component(nt);
  std::uint32_t components = 0;
  for (std::uint32_t t = 0; t < nt; ++t) {
    if (find_root(parent, t) == t) component[t] = components++;
  }
  for (std::uint32_t t = 0; t < nt; ++t) component[t] = component[find_root(parent, t)];
  std::vector<Sum> sums(components);
  auto pos = [&](Index i) { return Vec3(positions[i]); };
  for (std::uint32_t t = 0; t < nt; ++t) {
    Sum& s = sums[component[t]];
    for (Index v : triangles[t]) s.centroid = s.centroid + pos(v);
    s.count += 3;
    s.open += open_balance[t];
  }
  for (std::uint32_t t = 0; t < nt; ++t) {
    Sum& s = sums[component[t]];
    const Vec3 o = s.centroid * (1.0 / s.count);
    const Vec3 a = pos(triangles[t][0]) - o, b = pos(triangles[t][1]) - o,
               c = pos(triangles[t][2]) - o;
    s.volume += dot(a, cross(b, c));
    s.normal = s.normal + cross(b - a, c - a);
  }
  std::uint64_t flipped = 0;
  std::vector<std::uint8_t> flip(components, 0);
  for (std::uint32_t k = 0; k < components; ++k) {
    const Sum& s = sums[k];
    const bool vertical = s.open != 0 && std::abs(s.normal.z) > 0.5 * norm(s.normal);
    flip[k] = vertical ? s.normal.z < 0 : s.volume < 0;
    flipped += flip[k];
  }
  for (std::uint32_t t = 0; t < nt; ++t) {
    if (flip[component[t]]) std::swap(triangles[t][1], triangles[t][2]);
  }
  return flipped;
}

}  // namespace g2s
