// G2S mesh growing (docs/algorithm.md §2-4) over the points of one hash grid.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "g2s/mesher.hpp"
#include "grid/hash_grid.hpp"

namespace g2s {

// What a run starts from. Empty: a fresh tile, every point usable. The seam stitcher gives the
// triangles already kept around the seam, whose open edges become the front, and marks which
// points may join new triangles (the others are context for the Gabriel test only).
struct GrowContext {
  std::span<const Triangle> preload;  // in grid indices
  // Per preloaded triangle, a label: triangles with one label face consistently as given (they
  // start in one orientation group); empty: every triangle its own group.
  std::span<const std::uint32_t> preload_group;
  std::span<const std::uint8_t> growable;  // per grid point, non-zero: usable; empty: all
  // Pairs of labels known to face the same way (parity 0) or opposite ways (1) as given, joined
  // in this order before growing; a link that contradicts earlier ones is skipped.
  struct Link {
    std::uint32_t a, b;
    std::uint8_t parity;
  };
  std::span<const Link> preload_links;
  // How many more points, in Gabriel order, an edge tries when its Gabriel point cannot join.
  int retries = 0;
  // Per grid point, non-zero: may be a corner of a triangle that fills a hole, whether growable
  // or not (a tile's own points; at a seam, the points whose whole stars it loads: the band's and
  // the live ones of its context); empty: every growable one.
  std::span<const std::uint8_t> fillable;
  // The whole cloud's spacing (a tile's or a seam's grid sees only part of it), or 0: the
  // search radius is capped at max_radius times the larger of it and the lower confidence bound
  // of the grid's own spacing (HashGrid::spacing_lower_bound), so that a region denser than the
  // cloud bridges the gaps the cloud's sampling leaves, a sparser one reaches as far as its own
  // sampling needs, and a grid whose sampled spacing only seems larger does not reach farther
  // (one tile and many then cap alike). With 0, the cap is the grid's own spacing.
  double cloud_spacing = 0;
  // Per grid point, its position as the output holds it (the input's coordinates), where the
  // grid's floats are not exactly those less the frame's origin (coordinates finer than float):
  // crossings are then judged on these, so that the written mesh has none
  // (detail::CrossingPositions). Empty: the floats are exact. exact_origin: the frame's origin.
  std::span<const Vec3> exact_positions{};
  Vec3 exact_origin{0, 0, 0};
};

struct GrowResult {
  std::vector<Triangle> triangles;  // the new triangles, in grid indices
  // Orientation groups of the preloaded then the new triangles: triangles with the same group
  // face consistently once those with flip set have two corners swapped. Fronts from different
  // seeds (or tiles) may meet with either orientation; the groups record how they joined.
  std::vector<std::uint32_t> group;
  std::vector<std::uint8_t> flip;
  // Preloaded triangles taken off (sorted places in the context's preload): the ring around a
  // hole that could only be filled once widened, and scraps whose every point the run judges
  // (docs/algorithm.md, "Hole filling").
  std::vector<std::uint32_t> removed_preload;
  std::uint64_t seeds = 0;
  double seconds_finish = 0;  // wall seconds of the surface finishing (MeshReport::seconds_finish)
  // Points where a triangle started a second fan (fronts meeting at a point): the only places a
  // non-manifold vertex can be, in the order they arose.
  std::vector<Index> second_fans;
};

// Grows triangles from the preloaded front, then from seed triangles until no unused point can
// seed a new component. Deterministic: depends only on the grid (which is independent of input
// order), the context and the options.
GrowResult grow_mesh(const HashGrid& grid, const MeshOptions& options,
                     const GrowContext& context = {});

}  // namespace g2s
