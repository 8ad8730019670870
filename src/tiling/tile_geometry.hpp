// Box geometry of tiles, shared by the tiling and the pipeline's stages: distances between points
// and tile boxes, the bounds of all tiles, the tiles near a tile and their largest spacing.
#pragma once

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <span>
#include <vector>

#include "common/local_frame.hpp"
#include "g2s/tile_store.hpp"

namespace g2s {

inline double box_distance(const TileBox& box, const double* p) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double gap = std::max({box.lo[a] - p[a], 0.0, p[a] - box.hi[a]});
    d2 += gap * gap;
  }
  return std::sqrt(d2);
}

// `usual`, unless a frame on the box of the points it is for holds them at least 16 times finer
// (`usual` stretched toward stray points far from them). Short of that, the two frames differ
// only in how ties between points round, and `usual` is kept.
inline LocalFrame finer_frame(const LocalFrame& usual, const TileBox& points) {
  const LocalFrame on_points(points.lo, points.hi);
  return 16 * on_points.reach(points.lo, points.hi) <= usual.reach(points.lo, points.hi) ? on_points
                                                                                         : usual;
}

// The float frame a tile is meshed in: on its box, or on its points' box where that box reaches
// far beyond them (finer_frame). Its seams start from it.
inline LocalFrame tile_frame(const TileInfo& tile) {
  return finer_frame(LocalFrame(tile.box.lo, tile.box.hi), tile.points_box);
}

// The smallest box holding the points xyz (3 doubles each), or `empty` when there are none.
inline TileBox points_box(std::span<const double> xyz, const TileBox& empty) {
  if (xyz.size() < 3) return empty;
  TileBox b;
  for (int a = 0; a < 3; ++a) b.lo[a] = b.hi[a] = xyz[a];
  for (std::size_t i = 3; i + 2 < xyz.size(); i += 3) {
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::min(b.lo[a], xyz[i + a]);
      b.hi[a] = std::max(b.hi[a], xyz[i + a]);
    }
  }
  return b;
}

inline double box_gap(const TileBox& a, const TileBox& b) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max({a.lo[k] - b.hi[k], 0.0, b.lo[k] - a.hi[k]});
    d2 += gap * gap;
  }
  return std::sqrt(d2);
}

// A tile's box with the faces that other tiles lie beyond (open), and a point's depth measured
// from the open faces only. Tile boxes are cells of one k-d partition of the cloud's bounds, so
// every other tile lies wholly beyond some face of the box, and a point of the tile is at least
// its depth from the open faces away from every other tile: no seam comes nearer. A face with
// no tile beyond (one on the cloud's bounds, or facing only empty tiles) brings no seam, so a
// point near it alone is as deep as one in the middle: on a 5M-point torus cut into 9 tiles,
// 41% of the points lie within the stitcher's reach of some face of their box, 12% of an open
// one. Where another non-empty tile's box overlaps this one (not a partition), every face is
// open: the plain box depth.
struct TileFaces {
  TileBox box;
  bool open_lo[3] = {true, true, true};
  bool open_hi[3] = {true, true, true};

  // The distance from p (inside the box) to the nearest open face; infinite with none open.
  double depth(const double* p) const {
    double depth = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (open_lo[a]) depth = std::min(depth, p[a] - box.lo[a]);
      if (open_hi[a]) depth = std::min(depth, box.hi[a] - p[a]);
    }
    return depth;
  }
};

inline TileFaces tile_faces(std::span<const TileInfo> tiles, std::size_t tile) {
  const TileBox& box = tiles[tile].box;
  TileFaces faces{box};
  std::fill(std::begin(faces.open_lo), std::end(faces.open_lo), false);
  std::fill(std::begin(faces.open_hi), std::end(faces.open_hi), false);
  for (std::size_t j = 0; j < tiles.size(); ++j) {
    if (j == tile || tiles[j].points == 0) continue;
    bool beyond_a_face = false;
    for (int a = 0; a < 3; ++a) {
      if (tiles[j].box.lo[a] >= box.hi[a]) faces.open_hi[a] = beyond_a_face = true;
      if (tiles[j].box.hi[a] <= box.lo[a]) faces.open_lo[a] = beyond_a_face = true;
    }
    if (!beyond_a_face) return TileFaces{box};
  }
  return faces;
}

// The bounding box of all tiles: the cloud's.
inline TileBox tiles_bounds(std::span<const TileInfo> tiles) {
  TileBox b = tiles.empty() ? TileBox{} : tiles[0].box;
  for (const TileInfo& t : tiles) {
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::min(b.lo[a], t.box.lo[a]);
      b.hi[a] = std::max(b.hi[a], t.box.hi[a]);
    }
  }
  return b;
}

// The tiles other than `tile` whose boxes lie within `reach` of its box, in index order.
inline std::vector<std::size_t> tiles_near(std::span<const TileInfo> tiles, std::size_t tile,
                                           double reach) {
  std::vector<std::size_t> near;
  for (std::size_t j = 0; j < tiles.size(); ++j) {
    if (j != tile && tiles[j].points > 0 && box_gap(tiles[tile].box, tiles[j].box) <= reach) {
      near.push_back(j);
    }
  }
  return near;
}

// The largest spacing of a tile and its neighbours: the unit of the halo and seam widths, so
// that a sparse neighbour still gets a halo wide enough for its triangles.
inline double local_spacing(std::span<const TileInfo> tiles, std::size_t tile,
                            std::span<const std::size_t> near) {
  double s = tiles[tile].spacing;
  for (std::size_t j : near) s = std::max(s, tiles[j].spacing);
  return s;
}

}  // namespace g2s
