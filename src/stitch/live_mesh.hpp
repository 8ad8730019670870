// What the stitcher holds between tiles: the points some tile still to come can touch, and the
// triangles not yet handed on. Points live in slots (recycled, found by global id through an
// IdMap), so memory follows the band of unfinished seams, not the size of the cloud.
//
// Every point gets two steps when its tile arrives. After the last tile whose seam can still give
// it a triangle, it is finished: its star is complete and its fans are cleaned. Some steps later
// (a margin farther from the tiles to come) it is released: a triangle whose corners are all
// released leaves for the sink (src/cleanup/release.cpp). The margin keeps a finished point's
// triangles live while the clean-up of points finishing next to it may still delete some of
// them and so split its fan, which must then be judged again on its whole star.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cleanup/cleanup.hpp"
#include "common/id_map.hpp"
#include "common/union_find.hpp"
#include "g2s/error.hpp"
#include "g2s/types.hpp"

namespace g2s {

struct LiveMesh {
  static constexpr std::uint8_t kFinished = 1;
  static constexpr std::uint8_t kSuspect = 2;     // may have more than one fan
  static constexpr std::uint8_t kStarLoaded = 4;  // scratch of the seam being stitched
  static constexpr std::uint8_t kReleased = 8;
  static constexpr std::uint8_t kUnlisted = 16;   // not in slot_of: no seam will look it up
  static constexpr std::uint8_t kInContext = 32;  // scratch of the seam being stitched

  IdMap slot_of;  // global id -> slot
  std::vector<Index> id;
  std::vector<double> xyz;            // 3 per slot
  std::vector<std::uint32_t> number;  // vertex number given to the sink; kNoIndex before
  std::vector<std::uint32_t> uses;    // live triangles with this corner
  std::vector<std::uint8_t> flags;
  std::vector<std::uint32_t> release_step;  // the step after which the point is released
  std::vector<std::uint32_t> free_slots;
  std::vector<std::vector<std::uint32_t>> finishing;  // per step: the slots it finishes
  std::vector<std::vector<std::uint32_t>> releasing;  // per step: the slots it releases

  std::vector<Triangle> triangles;  // in slots
  std::vector<std::uint32_t> group;
  // Per triangle: the step that releases its last corner, so that finding the triangles a step
  // releases reads this array in order instead of three corners' flags each.
  std::vector<std::uint32_t> due;
  ParityUnionFind groups;
  std::vector<GroupSums> sums;  // per group

  std::size_t points = 0;  // live
  std::size_t peak_points = 0;

  explicit LiveMesh(std::size_t steps) : finishing(steps), releasing(steps) {}

  std::size_t capacity() const { return id.size(); }

  // A point of the tile being added, finished after step `finish` and released after `release`;
  // returns its slot. Only `listed` points can be found by id (slot()): the others lie where no
  // seam reaches, and leaving them out of the hash map saves a cache miss per point.
  std::uint32_t add_point(Index point, const double* p, std::uint32_t finish, std::uint32_t release,
                          bool listed) {
    std::uint32_t s = 0;
    if (free_slots.empty()) {
      s = static_cast<std::uint32_t>(id.size());
      id.push_back(point);
      xyz.insert(xyz.end(), p, p + 3);
      number.push_back(kNoIndex);
      uses.push_back(0);
      flags.push_back(0);
      release_step.push_back(release);
    } else {
      s = free_slots.back();
      free_slots.pop_back();
      id[s] = point;
      std::copy_n(p, 3, &xyz[3 * std::size_t{s}]);
      number[s] = kNoIndex;
      uses[s] = 0;
      flags[s] = 0;
      release_step[s] = release;
    }
    if (!listed) {
      flags[s] = kUnlisted;
    } else if (slot_of.insert(point, s) != s) {
      throw Error(Exit::bad_input, "tile store: a point id appears in two tiles");
    }
    finishing[finish].push_back(s);
    releasing[release].push_back(s);
    ++points;
    peak_points = std::max(peak_points, points);
    return s;
  }

  // The slot of a live point, or IdMap::kMissing.
  std::uint32_t slot(Index point) const { return slot_of.find(point); }

  std::uint32_t add_group() {
    sums.emplace_back();
    return groups.add();
  }

  void add_triangle(const Triangle& slots, std::uint32_t g) {
    triangles.push_back(slots);
    group.push_back(g);
    due.push_back(
        std::max({release_step[slots[0]], release_step[slots[1]], release_step[slots[2]]}));
    for (Index s : slots) ++uses[s];
  }

  // Takes the triangles at the sorted places `at` off, in place.
  void remove_triangles(const std::vector<std::uint32_t>& at) {
    std::size_t kept = 0, next = 0;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      if (next < at.size() && at[next] == t) {
        ++next;
        for (Index s : triangles[t]) --uses[s];
        continue;
      }
      triangles[kept] = triangles[t];
      group[kept] = group[t];
      due[kept] = due[t];
      ++kept;
    }
    triangles.resize(kept);
    group.resize(kept);
    due.resize(kept);
  }

  // Starts loading what releasing a triangle reads of its corner at slot s.
  void prefetch_corner(std::uint32_t s) const {
    __builtin_prefetch(&number[s]);
    __builtin_prefetch(&uses[s]);
    __builtin_prefetch(&id[s]);
    __builtin_prefetch(&xyz[3 * std::size_t{s}]);
  }

  // Starts loading what free_slot(s) will read: the slot's flags, uses and id, or (with those
  // loaded) the map entry it erases.
  void prefetch_slot(std::uint32_t s) const {
    __builtin_prefetch(&flags[s]);
    __builtin_prefetch(&uses[s]);
    __builtin_prefetch(&id[s]);
  }
  void prefetch_map_entry(std::uint32_t s) const {
    if (!(flags[s] & kUnlisted)) slot_of.prefetch(id[s]);
  }

  // Forgets a released point no live triangle uses.
  void free_slot(std::uint32_t s) {
    if (!(flags[s] & kUnlisted)) slot_of.erase(id[s]);
    --points;
    flags[s] = 0;
    free_slots.push_back(s);
  }
};

}  // namespace g2s
