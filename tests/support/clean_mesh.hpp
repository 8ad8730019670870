// The defect counts every mesh g2s makes must have at zero, asserted from g2s::compute_stats.
#pragma once

#include <gtest/gtest.h>

#include "g2s/stats.hpp"

namespace g2s::test_support {

// No non-manifold edge or vertex, orientation conflict, duplicate or degenerate triangle, and
// no crossing pair (the crossings must have been counted).
inline void expect_clean_mesh(const MeshStats& s) {
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_EQ(s.non_manifold_vertices, 0u);
  EXPECT_EQ(s.orientation_conflicts, 0u);
  EXPECT_EQ(s.duplicate_triangles, 0u);
  EXPECT_EQ(s.degenerate_triangles, 0u);
  ASSERT_TRUE(s.has_crossings);
  EXPECT_EQ(s.crossing_pairs, 0u);
}

}  // namespace g2s::test_support
