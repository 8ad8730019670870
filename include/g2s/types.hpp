// Plain data shared by every stage: point clouds and indexed meshes as flat arrays.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace g2s {

// Index of a point in its cloud. 32 bits: clouds of up to 4,294,967,295 points.
using Index = std::uint32_t;
inline constexpr Index kNoIndex = 0xFFFFFFFFu;

// Three corner indices; counter-clockwise seen from the side the normal points to.
using Triangle = std::array<Index, 3>;

// A point cloud exactly as read: xyz holds 3 doubles per point (x0 y0 z0 x1 ...). Doubles keep
// float and double input bit-exact, including georeferenced coordinates around 1e7.
struct PointCloud {
  std::vector<double> xyz;
  std::size_t size() const { return xyz.size() / 3; }
};

// A triangle mesh: vertex positions (3 doubles each) and triangles indexing them.
struct IndexedMesh {
  std::vector<double> xyz;
  std::vector<Triangle> triangles;
  std::size_t vertex_count() const { return xyz.size() / 3; }
};

}  // namespace g2s
