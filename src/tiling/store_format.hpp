// The tile store's byte layout (docs/tile-store.md has the table): offsets and sizes of the
// header, a tile table entry and a frame table entry, little-endian field access, and the
// border distance that orders a block's points. Shared by the writer and the reader so the two
// cannot disagree.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "g2s/tile_store.hpp"

namespace g2s::tiling {

inline constexpr char kMagic[8] = {'G', '2', 'S', 'T', 'I', 'L', 'E', 'S'};
// 1: no origin; 2: the input's identity and the tiling options (StoreOrigin) in the header;
// 3: the cloud's spacing in the header; 4: its group and twin distances; 5: each tile's points'
// box in its entry.
inline constexpr std::uint32_t kVersion = 5;
inline constexpr std::uint32_t kFlagCompressed = 1;
// Points per frame, the unit of compression and of checksums: load_border reads whole frames.
inline constexpr std::uint32_t kFramePoints = 16384;
// Bytes of a decoded point: x, y, z as double, then (in a separate run) the id as uint32.
inline constexpr std::size_t kPointBytes = 3 * sizeof(double) + sizeof(std::uint32_t);

// Header fields: byte offsets.
namespace header {
inline constexpr std::size_t magic = 0;                 // char[8]
inline constexpr std::size_t version = 8;               // u32
inline constexpr std::size_t header_bytes = 12;         // u32, = kHeaderBytes
inline constexpr std::size_t flags = 16;                // u32
inline constexpr std::size_t frame_points = 20;         // u32
inline constexpr std::size_t point_count = 24;          // u64
inline constexpr std::size_t tile_count = 32;           // u64
inline constexpr std::size_t bounds = 40;               // f64 lo[3], hi[3]
inline constexpr std::size_t input_declared = 88;       // u64
inline constexpr std::size_t input_points = 96;         // u64
inline constexpr std::size_t input_non_finite = 104;    // u64
inline constexpr std::size_t input_format = 112;        // char[16], zero-padded
inline constexpr std::size_t table_offset = 128;        // u64
inline constexpr std::size_t table_bytes = 136;         // u64
inline constexpr std::size_t file_bytes = 144;          // u64
inline constexpr std::size_t table_checksum = 152;      // u64, XXH64 of the tile table
inline constexpr std::size_t origin_bytes = 160;        // u64, the input's size
inline constexpr std::size_t origin_mtime = 168;        // i64, its modification time, ns
inline constexpr std::size_t origin_content = 176;      // u64, XXH64 of first MB, last MB, size
inline constexpr std::size_t origin_path = 184;         // u64, XXH64 of its absolute path
inline constexpr std::size_t origin_tile_points = 192;  // u64, the tile_points option
inline constexpr std::size_t cloud_spacing = 200;       // f64, the cloud's spacing
inline constexpr std::size_t twin_distance = 208;       // f64, 0 unless a cloud of twins
inline constexpr std::size_t group_distance = 216;      // f64, 0 unless points come in groups
inline constexpr std::size_t header_checksum = 248;     // u64, XXH64 of bytes [0, 248)
}  // namespace header
inline constexpr std::size_t kHeaderBytes = 256;
inline constexpr std::size_t kFormatChars = 16;

// Tile table entry fields.
namespace entry {
inline constexpr std::size_t box = 0;                    // f64 lo[3], hi[3]
inline constexpr std::size_t points = 48;                // u64
inline constexpr std::size_t spacing = 56;               // f64
inline constexpr std::size_t block_offset = 64;          // u64, from the start of the file
inline constexpr std::size_t block_bytes = 72;           // u64
inline constexpr std::size_t frame_table_checksum = 80;  // u64, XXH64 of the block's frame table
inline constexpr std::size_t points_box = 88;            // f64 lo[3], hi[3]
}  // namespace entry
inline constexpr std::size_t kEntryBytes = 136;

// Frame table entry fields (the frame table opens each block).
namespace frame {
inline constexpr std::size_t offset = 0;           // u64, from the start of the block
inline constexpr std::size_t stored_bytes = 8;     // u64
inline constexpr std::size_t first_distance = 16;  // f64, border distance of its first point
inline constexpr std::size_t checksum = 24;        // u64, XXH64 of the stored bytes
}  // namespace frame
inline constexpr std::size_t kFrameEntryBytes = 32;

inline std::uint64_t frame_count(std::uint64_t points, std::uint64_t frame_points) {
  return (points + frame_points - 1) / frame_points;
}

template <typename U>
inline U byte_swap(U u) {
  if constexpr (sizeof(U) == 4) {
    return __builtin_bswap32(u);
  } else {
    return __builtin_bswap64(u);
  }
}

template <typename T>
inline void store_le(unsigned char* dst, T value) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  using U = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
  U u = std::bit_cast<U>(value);
  if constexpr (std::endian::native == std::endian::big) u = byte_swap(u);
  std::memcpy(dst, &u, sizeof u);
}

template <typename T>
inline T load_le(const unsigned char* src) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  using U = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
  U u;
  std::memcpy(&u, src, sizeof u);
  if constexpr (std::endian::native == std::endian::big) u = byte_swap(u);
  return std::bit_cast<T>(u);
}

// The faces of a tile's box that border a neighbour, as planes a point's distance is measured
// to: a face on the cloud's bounding box borders nothing and is pushed to infinity.
struct BorderFaces {
  double lo[3];
  double hi[3];

  BorderFaces(const TileBox& box, const TileBox& bounds) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      lo[a] = box.lo[a] == bounds.lo[a] ? -inf : box.lo[a];
      hi[a] = box.hi[a] == bounds.hi[a] ? inf : box.hi[a];
    }
  }

  // Distance from p (inside the box) to the nearest bordering face; +inf if there is none.
  double distance(const double* p) const {
    double d = std::min(p[0] - lo[0], hi[0] - p[0]);
    d = std::min(d, std::min(p[1] - lo[1], hi[1] - p[1]));
    return std::min(d, std::min(p[2] - lo[2], hi[2] - p[2]));
  }
};

}  // namespace g2s::tiling
