// Tests of TileFaces (src/tiling/tile_geometry.hpp): a point's depth counts only the faces of its
// tile's box that other, non-empty tiles lie beyond, and it is never more than the point's
// distance to another tile's box; boxes that are not a partition fall back to the plain depth.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "tiling/tile_geometry.hpp"

namespace g2s {
namespace {

TileInfo tile_at(double x0, double x1, double y0, double y1, std::uint64_t points = 100) {
  TileInfo t{};
  t.box.lo[0] = x0, t.box.hi[0] = x1;
  t.box.lo[1] = y0, t.box.hi[1] = y1;
  t.box.lo[2] = 0, t.box.hi[2] = 1;
  t.points = points;
  return t;
}

// Two columns of two tiles over [0, 2] x [0, 2] x [0, 1].
std::vector<TileInfo> two_by_two() {
  return {tile_at(0, 1, 0, 1), tile_at(1, 2, 0, 1), tile_at(0, 1, 1, 2), tile_at(1, 2, 1, 2)};
}

TEST(TileFaces, OnlyFacesWithATileBeyondCount) {
  const std::vector<TileInfo> tiles = two_by_two();
  const TileFaces faces = tile_faces(tiles, 0);
  EXPECT_FALSE(faces.open_lo[0]);
  EXPECT_TRUE(faces.open_hi[0]);
  EXPECT_FALSE(faces.open_lo[1]);
  EXPECT_TRUE(faces.open_hi[1]);
  EXPECT_FALSE(faces.open_lo[2]);
  EXPECT_FALSE(faces.open_hi[2]);
  // Next to the cloud's bounds (x = 0.01, z = 0.01), far from the other tiles.
  const double near_bounds[3] = {0.01, 0.2, 0.01};
  EXPECT_DOUBLE_EQ(faces.depth(near_bounds), 0.8);
  const double near_tile_1[3] = {0.95, 0.5, 0.5};
  EXPECT_NEAR(faces.depth(near_tile_1), 0.05, 1e-15);
}

TEST(TileFaces, DepthNeverExceedsTheDistanceToAnotherTile) {
  const std::vector<TileInfo> tiles = two_by_two();
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const TileFaces faces = tile_faces(tiles, t);
    for (int i = 0; i <= 10; ++i) {
      for (int j = 0; j <= 10; ++j) {
        const double p[3] = {tiles[t].box.lo[0] + 0.1 * i, tiles[t].box.lo[1] + 0.1 * j, 0.3};
        for (std::size_t o = 0; o < tiles.size(); ++o) {
          if (o == t) continue;
          EXPECT_LE(faces.depth(p), box_distance(tiles[o].box, p) + 1e-12);
        }
      }
    }
  }
}

TEST(TileFaces, EmptyTilesOpenNoFaceAndALoneTileHasNone) {
  std::vector<TileInfo> tiles = two_by_two();
  tiles[1].points = 0;
  tiles[3].points = 0;
  const TileFaces faces = tile_faces(tiles, 0);
  EXPECT_FALSE(faces.open_hi[0]);
  EXPECT_TRUE(faces.open_hi[1]);
  const std::vector<TileInfo> alone = {tile_at(0, 1, 0, 1)};
  const double middle[3] = {0.5, 0.5, 0.5};
  EXPECT_EQ(tile_faces(alone, 0).depth(middle), std::numeric_limits<double>::infinity());
}

TEST(TileFaces, OverlappingBoxesOpenEveryFace) {
  const std::vector<TileInfo> tiles = {tile_at(0, 1, 0, 1), tile_at(0.5, 1.5, 0, 1)};
  const TileFaces faces = tile_faces(tiles, 0);
  for (int a = 0; a < 3; ++a) {
    EXPECT_TRUE(faces.open_lo[a]);
    EXPECT_TRUE(faces.open_hi[a]);
  }
  const double p[3] = {0.1, 0.5, 0.5};
  EXPECT_NEAR(faces.depth(p), 0.1, 1e-15);
}

}  // namespace
}  // namespace g2s
