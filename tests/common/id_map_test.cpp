// The stitcher's id -> slot hash map (src/common/id_map.hpp) against std::unordered_map under
// random inserts, lookups and erases: backward-shift deletion must keep every remaining id
// findable, including across growth of the table and in long probe runs.
#include "common/id_map.hpp"

#include <gtest/gtest.h>

#include <random>
#include <unordered_map>
#include <vector>

namespace {

TEST(IdMap, AgreesWithUnorderedMapUnderRandomInsertsAndErases) {
  std::mt19937 random(7);
  for (const std::uint32_t range : {64u, 5000u, 1u << 30}) {  // dense ids: long probe runs
    g2s::IdMap map;
    std::unordered_map<g2s::Index, std::uint32_t> reference;
    std::uniform_int_distribution<std::uint32_t> id(0, range - 1);
    for (int step = 0; step < 200000; ++step) {
      const g2s::Index key = id(random);
      const auto value = static_cast<std::uint32_t>(step);
      switch (random() % 3) {
        case 0: {
          const auto [at, added] = reference.emplace(key, value);
          ASSERT_EQ(map.insert(key, value), at->second) << "key " << key;
          break;
        }
        case 1:
          map.erase(key);
          reference.erase(key);
          break;
        default: {
          const auto at = reference.find(key);
          ASSERT_EQ(map.find(key), at == reference.end() ? g2s::IdMap::kMissing : at->second)
              << "key " << key << " at step " << step;
        }
      }
      ASSERT_EQ(map.size(), reference.size());
    }
    for (const auto& [key, value] : reference) ASSERT_EQ(map.find(key), value);
    map.clear();
    EXPECT_EQ(map.size(), 0u);
    for (const auto& entry : reference) EXPECT_EQ(map.find(entry.first), g2s::IdMap::kMissing);
  }
}

}  // namespace
