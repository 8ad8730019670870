// G2S mesh growing (ALGORITHM.md §3-5) over the points of one hash grid.
#pragma once

#include <cstdint>
#include <vector>

#include "g2s/mesher.hpp"
#include "grid/hash_grid.hpp"

namespace g2s {

struct GrowResult {
  std::vector<Triangle> triangles;  // in grid indices; consistently oriented per component
  std::uint64_t seeds = 0;
  // Points where a triangle started a second fan (fronts meeting at a point): the only places a
  // non-manifold vertex can be, in the order they arose.
  std::vector<Index> second_fans;
};

// Grows triangles from seed triangles until no unused point can seed a new component.
// Deterministic: depends only on the grid (which is independent of input order) and options.
GrowResult grow_mesh(const HashGrid& grid, const MeshOptions& options);

}  // namespace g2s
