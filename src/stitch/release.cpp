// Finishing points and releasing triangles as the stitcher sweeps the tiles. A point is finished
// after the last step that can touch it (LiveMesh), so its star is complete: its fans can be
// judged exactly as the in-memory pass would. A triangle with three released corners can change
// no more except for the orientation of its group, decided at the very end.
#include "stitch/release.hpp"

#include <utility>

namespace g2s {

void add_to_sums(GroupSums& s, const std::array<const double*, 3>& xyz, const Vec3& origin,
                 const Triangle& ids) {
  auto at = [&](int k) { return Vec3{xyz[k][0], xyz[k][1], xyz[k][2]} - origin; };
  const Vec3 pa = at(0), pb = at(1), pc = at(2);
  s.det += dot(pa, cross(pb, pc));
  s.normal = s.normal + cross(pb - pa, pc - pa);
  s.centroid = s.centroid + pa + pb + pc;
  s.corners += 3;
  s.edge_keys ^= edge_key(ids[0], ids[1]) ^ edge_key(ids[1], ids[2]) ^ edge_key(ids[2], ids[0]);
}

void emit_triangle(const std::array<std::uint32_t*, 3>& number,
                   const std::array<const double*, 3>& xyz, const Triangle& ids, GroupSums& sums,
                   std::uint32_t group, const Vec3& origin, MeshSink& sink, ReleaseCounts& counts) {
  Triangle numbers{};
  for (int k = 0; k < 3; ++k) {
    if (*number[k] == kNoIndex) {
      *number[k] = counts.vertices++;
      sink.vertex(ids[k], xyz[k]);
    }
    numbers[k] = *number[k];
  }
  sink.triangle(numbers, xyz, group);
  ++counts.triangles;
  add_to_sums(sums, xyz, origin, ids);
}

void release_finished(LiveMesh& live, std::size_t step, const Vec3& origin, MeshSink& sink,
                      ReleaseCounts& counts) {
  // Taken out of the lists (not cleared in place, which would keep their capacity).
  const std::vector<std::uint32_t> finishing = std::exchange(live.finishing[step], {});
  std::vector<Index> suspects;
  for (std::uint32_t s : finishing) {
    live.flags[s] |= LiveMesh::kFinished;
    if (live.flags[s] & LiveMesh::kSuspect) suspects.push_back(s);
  }
  // Slots that may be free once this step's triangles are gone.
  std::vector<std::uint32_t> maybe_free = std::exchange(live.releasing[step], {});
  for (std::uint32_t s : maybe_free) live.flags[s] |= LiveMesh::kReleased;
  std::vector<std::uint8_t> dead;
  if (!suspects.empty()) {
    // Finished points with a triangle already handed on cannot be judged again (their star is
    // no longer whole): the release margin makes that rare, and it is counted.
    std::vector<std::uint8_t> finished(live.capacity());
    for (std::size_t s = 0; s < finished.size(); ++s) {
      if (live.flags[s] & LiveMesh::kFinished) finished[s] = live.number[s] == kNoIndex ? 1 : 2;
    }
    std::vector<Index> deferred;
    const NonManifoldReport nm =
        mark_non_manifold_fans(live.triangles, live.capacity(), suspects, finished, dead, deferred);
    counts.non_manifold.vertices_fixed += nm.vertices_fixed;
    counts.non_manifold.triangles_removed += nm.triangles_removed;
    counts.non_manifold.vertices_unjudged += nm.vertices_unjudged;
    for (Index s : deferred) live.flags[s] |= LiveMesh::kSuspect;
  }
  // Both loops below are bound by memory latency (the corners' slots lie scattered): each starts
  // loading what it will read a few iterations ahead.
  constexpr std::size_t kAhead = 8;
  std::size_t kept = 0;
  for (std::size_t t = 0; t < live.triangles.size(); ++t) {
    if (t + kAhead < live.triangles.size() && live.due[t + kAhead] <= step) {
      for (Index s : live.triangles[t + kAhead]) live.prefetch_corner(s);
    }
    const bool removed = !dead.empty() && dead[t];
    const bool released = live.due[t] <= step;
    if (!removed && !released) {
      live.triangles[kept] = live.triangles[t];
      live.group[kept] = live.group[t];
      live.due[kept] = live.due[t];
      ++kept;
      continue;
    }
    const Triangle tri = live.triangles[t];
    if (!removed) {
      emit_triangle({&live.number[tri[0]], &live.number[tri[1]], &live.number[tri[2]]},
                    {&live.xyz[3 * std::size_t{tri[0]}], &live.xyz[3 * std::size_t{tri[1]}],
                     &live.xyz[3 * std::size_t{tri[2]}]},
                    {live.id[tri[0]], live.id[tri[1]], live.id[tri[2]]}, live.sums[live.group[t]],
                    live.group[t], origin, sink, counts);
    }
    for (Index s : tri) {
      --live.uses[s];
      maybe_free.push_back(s);
    }
  }
  live.triangles.resize(kept);
  live.group.resize(kept);
  live.due.resize(kept);
  const auto may_free = [&](std::uint32_t s) {
    return (live.flags[s] & LiveMesh::kReleased) && live.uses[s] == 0;
  };
  for (std::size_t k = 0; k < maybe_free.size(); ++k) {
    // The slot two steps ahead, then the map entry of one that will be freed.
    if (k + 2 * kAhead < maybe_free.size()) live.prefetch_slot(maybe_free[k + 2 * kAhead]);
    if (k + kAhead < maybe_free.size() && may_free(maybe_free[k + kAhead])) {
      live.prefetch_map_entry(maybe_free[k + kAhead]);
    }
    const std::uint32_t s = maybe_free[k];
    if (may_free(s)) {
      if (live.number[s] != kNoIndex) sink.vertex_done(live.number[s]);
      live.free_slot(s);
    }
  }
}

}  // namespace g2s
