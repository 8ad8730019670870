// The largest connected piece of a mesh (include/g2s/stats.hpp: largest_component), so that a
// scan's own surface can be measured apart from stray patches, such as the small pieces a
// mesher makes of outliers (docs/robustness.md).
#include <algorithm>
#include <numeric>
#include <vector>

#include "common/union_find.hpp"
#include "g2s/error.hpp"
#include "g2s/stats.hpp"

namespace g2s {

IndexedMesh largest_component(const IndexedMesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  if (n > kNoIndex) throw Error(Exit::bad_input, "mesh has more than 4,294,967,295 vertices");
  std::vector<std::uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0u);
  for (const Triangle& t : mesh.triangles) {
    for (const Index v : t) {
      if (v >= n) throw Error(Exit::bad_input, "a triangle indexes a vertex past the end");
    }
    for (int k = 1; k < 3; ++k) {
      const std::uint32_t a = find_root(parent, t[0]), b = find_root(parent, t[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  // Triangles per root; then, in triangle order, the first root with the largest count.
  std::vector<std::uint64_t> count(n, 0);
  std::uint64_t most = 0;
  for (const Triangle& t : mesh.triangles) most = std::max(most, ++count[find_root(parent, t[0])]);
  Index best = kNoIndex;
  for (const Triangle& t : mesh.triangles) {
    const std::uint32_t r = find_root(parent, t[0]);
    if (count[r] == most) {
      best = r;
      break;
    }
  }
  IndexedMesh out{mesh.xyz, {}};
  for (const Triangle& t : mesh.triangles) {
    if (find_root(parent, t[0]) == best) out.triangles.push_back(t);
  }
  return out;
}

}  // namespace g2s
