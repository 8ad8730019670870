// TileStore (docs/tile-store.md "Loading a tile and its halo"): validates the header and the tile
// table once, then loads a tile's frames on demand, checking each frame's checksum as it is read.
// The store is read with pread into per-thread buffers, not mapped: a mapped store's pages stayed
// resident after every load (the kernel maps whole page-cache folios around a fault, up to 2 MiB,
// beyond any margin a release could guess), and held 44% of the store at small budgets. Nothing
// is modified after opening, so loads from several threads need no locking.
#include <fmt/core.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/tile_store.hpp"
#include "io/mapped_file.hpp"
#include "tiling/store_format.hpp"
#include "tiling/xxhash64.hpp"

namespace g2s {

using namespace tiling;

namespace {

// One decompression context per thread, reused across frames and loads (tiles are loaded from
// several TBB tasks at once; a context must not be shared).
ZSTD_DCtx* thread_decompressor() {
  struct Holder {
    ZSTD_DCtx* context = ZSTD_createDCtx();
    ~Holder() { ZSTD_freeDCtx(context); }
  };
  thread_local Holder holder;
  return holder.context;
}

}  // namespace

struct TileStore::Impl {
  std::filesystem::path path;
  io::InputFile file;
  bool compressed = false;
  std::uint64_t frame_points = 0;
  std::uint64_t point_count = 0;
  TileBox bounds;
  ReadReport input;
  StoreOrigin origin;
  double cloud_spacing = 0;
  double twin_distance = 0;
  double group_distance = 0;
  std::vector<TileInfo> tiles;
  std::vector<std::uint64_t> block_offset;
  std::vector<std::uint64_t> block_bytes;
  std::vector<std::uint64_t> frame_table_checksum;

  explicit Impl(const std::filesystem::path& store) : path(store), file(store) {}

  // Reads [offset, offset + bytes) of the store into `out`.
  void read(std::uint64_t offset, std::uint64_t bytes, std::vector<unsigned char>& out) const {
    out.resize(bytes);
    file.read_at(offset, out.data(), bytes);
  }

  template <typename... Args>
  [[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) const {
    throw Error(Exit::bad_input,
                file.name() + ": " + fmt::format(format, std::forward<Args>(args)...));
  }

  void open();
  void read_table(const unsigned char* table, std::uint64_t first_block, std::uint64_t end);
  const unsigned char* frame_table(std::size_t tile) const;
  TilePoints decode(std::size_t tile, const unsigned char* table, std::uint64_t frames) const;
};

void TileStore::Impl::open() {
  const std::uint64_t size = file.size();
  if (size == 0) fail("file is empty (expected a g2s tile store)");
  std::vector<unsigned char> header_bytes_read;
  read(0, std::min<std::uint64_t>(size, kHeaderBytes), header_bytes_read);
  const unsigned char* h = header_bytes_read.data();
  if (std::memcmp(h, kMagic, std::min<std::uint64_t>(size, sizeof kMagic)) != 0) {
    fail("not a g2s tile store (it does not start with the magic bytes 'G2STILES')");
  }
  if (size >= header::version + 4) {
    const auto version = load_le<std::uint32_t>(h + header::version);
    if (version != kVersion) {
      fail("store version {}, this g2s reads {} (tile the cloud again with this g2s)", version,
           kVersion);
    }
  }
  if (size < kHeaderBytes) {
    fail("truncated: {} bytes, shorter than the {}-byte header", size, kHeaderBytes);
  }
  if (xxhash64(h, header::header_checksum) != load_le<std::uint64_t>(h + header::header_checksum)) {
    fail("header checksum mismatch (the header is corrupt)");
  }
  const auto header_bytes = load_le<std::uint32_t>(h + header::header_bytes);
  if (header_bytes != kHeaderBytes) {
    fail("header size {} (version {} has {})", header_bytes, kVersion, kHeaderBytes);
  }
  const auto flags = load_le<std::uint32_t>(h + header::flags);
  if ((flags & ~kFlagCompressed) != 0) fail("unknown header flags 0x{:x}", flags);
  compressed = (flags & kFlagCompressed) != 0;
  frame_points = load_le<std::uint32_t>(h + header::frame_points);
  if (frame_points == 0) fail("header: 0 points per frame");
  const auto file_bytes = load_le<std::uint64_t>(h + header::file_bytes);
  if (size < file_bytes) fail("truncated: {} bytes, the header says {}", size, file_bytes);
  if (size > file_bytes) fail("{} bytes, the header says {} (bytes appended?)", size, file_bytes);
  point_count = load_le<std::uint64_t>(h + header::point_count);
  const auto tile_count = load_le<std::uint64_t>(h + header::tile_count);
  for (int a = 0; a < 3; ++a) {
    bounds.lo[a] = load_le<double>(h + header::bounds + 8 * a);
    bounds.hi[a] = load_le<double>(h + header::bounds + 24 + 8 * a);
    if (!(bounds.lo[a] <= bounds.hi[a]) || !std::isfinite(bounds.lo[a]) ||
        !std::isfinite(bounds.hi[a])) {
      fail("header: bounds [{}, {}] on axis {} are not a box", bounds.lo[a], bounds.hi[a], a);
    }
  }
  input.declared = load_le<std::uint64_t>(h + header::input_declared);
  input.points = load_le<std::uint64_t>(h + header::input_points);
  input.non_finite = load_le<std::uint64_t>(h + header::input_non_finite);
  const char* format = reinterpret_cast<const char*>(h + header::input_format);
  input.format.assign(format, strnlen(format, kFormatChars));
  origin.bytes = load_le<std::uint64_t>(h + header::origin_bytes);
  origin.mtime_ns = load_le<std::int64_t>(h + header::origin_mtime);
  origin.content = load_le<std::uint64_t>(h + header::origin_content);
  origin.path = load_le<std::uint64_t>(h + header::origin_path);
  origin.tile_points = load_le<std::uint64_t>(h + header::origin_tile_points);
  cloud_spacing = load_le<double>(h + header::cloud_spacing);
  if (!(cloud_spacing >= 0) || !std::isfinite(cloud_spacing)) {
    fail("header: cloud spacing {} is not a length", cloud_spacing);
  }
  twin_distance = load_le<double>(h + header::twin_distance);
  if (!(twin_distance >= 0) || !(twin_distance <= cloud_spacing)) {
    fail("header: twin distance {} is not a length below the spacing", twin_distance);
  }
  group_distance = load_le<double>(h + header::group_distance);
  if (!(group_distance >= twin_distance) || !(group_distance <= cloud_spacing)) {
    fail("header: group distance {} is not a length between the twin distance and the spacing",
         group_distance);
  }
  const auto table_offset = load_le<std::uint64_t>(h + header::table_offset);
  const auto table_bytes = load_le<std::uint64_t>(h + header::table_bytes);
  if (table_offset != kHeaderBytes || tile_count > size / kEntryBytes ||
      table_bytes != tile_count * kEntryBytes || table_bytes > size - table_offset) {
    fail("header: tile table of {} tiles ({} bytes at {}) does not fit the {}-byte file",
         tile_count, table_bytes, table_offset, size);
  }
  std::vector<unsigned char> table;
  read(table_offset, table_bytes, table);
  if (xxhash64(table.data(), table_bytes) != load_le<std::uint64_t>(h + header::table_checksum)) {
    fail("tile table checksum mismatch (the table is corrupt)");
  }
  tiles.resize(tile_count);
  block_offset.resize(tile_count);
  block_bytes.resize(tile_count);
  frame_table_checksum.resize(tile_count);
  read_table(table.data(), table_offset + table_bytes, file_bytes);
}

// Reads the tile table and checks that it describes the file: blocks in tile order, back to
// back up to the end, each large enough for its frame table; boxes inside the bounds; counts
// adding up to the header's.
void TileStore::Impl::read_table(const unsigned char* table, std::uint64_t first_block,
                                 std::uint64_t end) {
  std::uint64_t next_block = first_block;
  std::uint64_t points = 0;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const unsigned char* e = table + t * kEntryBytes;
    TileInfo& info = tiles[t];
    for (int a = 0; a < 3; ++a) {
      info.box.lo[a] = load_le<double>(e + entry::box + 8 * a);
      info.box.hi[a] = load_le<double>(e + entry::box + 24 + 8 * a);
      if (!(bounds.lo[a] <= info.box.lo[a] && info.box.lo[a] <= info.box.hi[a] &&
            info.box.hi[a] <= bounds.hi[a])) {
        fail("tile {}: box [{}, {}] on axis {} is not inside the bounds", t, info.box.lo[a],
             info.box.hi[a], a);
      }
    }
    for (int a = 0; a < 3; ++a) {
      info.points_box.lo[a] = load_le<double>(e + entry::points_box + 8 * a);
      info.points_box.hi[a] = load_le<double>(e + entry::points_box + 24 + 8 * a);
      if (!(info.box.lo[a] <= info.points_box.lo[a] &&
            info.points_box.lo[a] <= info.points_box.hi[a] &&
            info.points_box.hi[a] <= info.box.hi[a])) {
        fail("tile {}: its points' box [{}, {}] on axis {} is not inside its box", t,
             info.points_box.lo[a], info.points_box.hi[a], a);
      }
    }
    info.points = load_le<std::uint64_t>(e + entry::points);
    info.spacing = load_le<double>(e + entry::spacing);
    block_offset[t] = load_le<std::uint64_t>(e + entry::block_offset);
    block_bytes[t] = load_le<std::uint64_t>(e + entry::block_bytes);
    frame_table_checksum[t] = load_le<std::uint64_t>(e + entry::frame_table_checksum);
    if (info.points > kNoIndex || !(info.spacing >= 0) || !std::isfinite(info.spacing)) {
      fail("tile {}: {} points, spacing {}: not a tile", t, info.points, info.spacing);
    }
    if (block_offset[t] != next_block || block_bytes[t] > end - next_block ||
        block_bytes[t] < frame_count(info.points, frame_points) * kFrameEntryBytes) {
      fail(
          "tile {}: block of {} bytes at {} does not follow the previous one (expected at {}, "
          "within {} bytes)",
          t, block_bytes[t], block_offset[t], next_block, end);
    }
    const std::uint64_t raw_bytes =
        frame_count(info.points, frame_points) * kFrameEntryBytes + info.points * kPointBytes;
    if (!compressed && block_bytes[t] != raw_bytes) {
      fail("tile {}: raw block of {} bytes for {} points (expected {})", t, block_bytes[t],
           info.points, raw_bytes);
    }
    next_block += block_bytes[t];
    points += info.points;
  }
  if (next_block != end) {
    fail("the blocks end at byte {}, the file at {} (corrupt table)", next_block, end);
  }
  if (points != point_count) {
    fail("the tiles hold {} points, the header says {} (corrupt table)", points, point_count);
  }
}

// The frame table that opens a tile's block, read into this thread's buffer and checked
// against its checksum.
const unsigned char* TileStore::Impl::frame_table(std::size_t tile) const {
  if (tile >= tiles.size()) {
    throw Error(Exit::failure, fmt::format("{}: tile {} asked for; the store has {} tiles",
                                           file.name(), tile, tiles.size()));
  }
  thread_local std::vector<unsigned char> table;
  const std::uint64_t table_bytes =
      frame_count(tiles[tile].points, frame_points) * kFrameEntryBytes;
  read(block_offset[tile], table_bytes, table);
  if (xxhash64(table.data(), table_bytes) != frame_table_checksum[tile]) {
    fail("tile {}: frame table checksum mismatch (the block is corrupt)", tile);
  }
  return table.data();
}

// The points of a tile's first `frames` frames, each read and checked against its checksum.
TilePoints TileStore::Impl::decode(std::size_t tile, const unsigned char* table,
                                   std::uint64_t frames) const {
  const TileInfo& info = tiles[tile];
  const std::uint64_t all_frames = frame_count(info.points, frame_points);
  const std::uint64_t points = std::min(info.points, frames * frame_points);
  TilePoints out;
  out.xyz.resize(points * 3);
  out.ids.resize(points);
  thread_local std::vector<unsigned char> stored, unpacked;
  std::uint64_t expected_offset = all_frames * kFrameEntryBytes;
  for (std::uint64_t f = 0; f < frames; ++f) {
    const unsigned char* e = table + f * kFrameEntryBytes;
    const auto offset = load_le<std::uint64_t>(e + frame::offset);
    const auto stored_bytes = load_le<std::uint64_t>(e + frame::stored_bytes);
    if (offset != expected_offset || stored_bytes > block_bytes[tile] - offset) {
      fail("tile {} frame {}: {} bytes at {} lie outside the block (corrupt block)", tile, f,
           stored_bytes, offset);
    }
    expected_offset += stored_bytes;
    read(block_offset[tile] + offset, stored_bytes, stored);
    if (xxhash64(stored.data(), stored_bytes) != load_le<std::uint64_t>(e + frame::checksum)) {
      fail("tile {} frame {}: checksum mismatch (the block is corrupt)", tile, f);
    }
    const std::uint64_t first = f * frame_points;
    const std::size_t m = std::min(frame_points, info.points - first);
    const std::size_t raw_bytes = m * kPointBytes;
    const unsigned char* raw = stored.data();
    if (compressed) {
      unpacked.resize(raw_bytes);
      const std::size_t got = ZSTD_decompressDCtx(thread_decompressor(), unpacked.data(), raw_bytes,
                                                  stored.data(), stored_bytes);
      if (ZSTD_isError(got) || got != raw_bytes) {
        fail("tile {} frame {}: does not decompress to {} points ({})", tile, f, m,
             ZSTD_isError(got) ? ZSTD_getErrorName(got) : "wrong size");
      }
      raw = unpacked.data();
    } else if (stored_bytes != raw_bytes) {
      fail("tile {} frame {}: {} bytes, expected {} for {} points", tile, f, stored_bytes,
           raw_bytes, m);
    }
    double* xyz = out.xyz.data() + 3 * first;
    for (std::size_t k = 0; k < 3 * m; ++k) xyz[k] = load_le<double>(raw + k * sizeof(double));
    const unsigned char* ids = raw + 3 * m * sizeof(double);
    Index* id = out.ids.data() + first;
    for (std::size_t k = 0; k < m; ++k) id[k] = load_le<std::uint32_t>(ids + k * sizeof(Index));
  }
  if (frames == all_frames && expected_offset != block_bytes[tile]) {
    fail("tile {}: the frames end at byte {} of a {}-byte block (corrupt block)", tile,
         expected_offset, block_bytes[tile]);
  }
  return out;
}

TileStore::TileStore(const std::filesystem::path& store) : impl_(std::make_unique<Impl>(store)) {
  impl_->open();
}

TileStore::~TileStore() = default;

const std::filesystem::path& TileStore::path() const {
  return impl_->path;
}
const TileBox& TileStore::bounds() const {
  return impl_->bounds;
}
double TileStore::cloud_spacing() const {
  return impl_->cloud_spacing;
}

double TileStore::twin_distance() const {
  return impl_->twin_distance;
}

double TileStore::group_distance() const {
  return impl_->group_distance;
}
std::span<const TileInfo> TileStore::tiles() const {
  return impl_->tiles;
}
const StoreOrigin& TileStore::origin() const {
  return impl_->origin;
}
const ReadReport& TileStore::input_report() const {
  return impl_->input;
}
bool TileStore::compressed() const {
  return impl_->compressed;
}

TilePoints TileStore::load(std::size_t tile) const {
  const unsigned char* table = impl_->frame_table(tile);
  return impl_->decode(tile, table, frame_count(impl_->tiles[tile].points, impl_->frame_points));
}

TilePoints TileStore::load_border(std::size_t tile, double distance) const {
  const unsigned char* table = impl_->frame_table(tile);
  const TileInfo& info = impl_->tiles[tile];
  // Frames are in increasing border distance: read those starting within `distance`.
  const std::uint64_t all_frames = frame_count(info.points, impl_->frame_points);
  std::uint64_t frames = 0;
  while (frames < all_frames &&
         load_le<double>(table + frames * kFrameEntryBytes + frame::first_distance) <= distance) {
    ++frames;
  }
  TilePoints out = impl_->decode(tile, table, frames);
  // The last frame read may go past `distance`: cut at the first point beyond it, by the
  // distance the writer sorted on, recomputed from the point itself.
  const BorderFaces faces(info.box, impl_->bounds);
  std::size_t lo = 0, hi = out.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (faces.distance(&out.xyz[3 * mid]) <= distance) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  out.xyz.resize(3 * lo);
  out.ids.resize(lo);
  return out;
}

bool kept_store_matches(const std::filesystem::path& store, const std::filesystem::path& input,
                        std::uint64_t tile_points, std::string& why) {
  std::error_code error;
  if (!std::filesystem::exists(store, error)) return false;
  {
    char magic[8] = {};
    std::ifstream in(store, std::ios::binary);
    in.read(magic, sizeof magic);
    if (!std::filesystem::is_regular_file(store, error) || !in ||
        std::string_view(magic, sizeof magic) != "G2STILES") {
      throw Error(Exit::usage, fmt::format("{}: the file there is not a g2s tile store; refusing "
                                           "to overwrite it (choose another path)",
                                           store.string()));
    }
  }
  try {
    const TileStore kept(store);
    if (kept.origin() == store_origin(input, tile_points)) return true;
    why = kept.origin().tile_points != tile_points
              ? fmt::format(
                    "was cut into tiles of at most {} points, not {} (--tile-points, "
                    "--memory)",
                    kept.origin().tile_points, tile_points)
              : fmt::format("was made from another file or version of {}", input.string());
  } catch (const Error& e) {
    if (e.code() != Exit::bad_input) throw;
    why = fmt::format("cannot be reused ({})", e.what());
  }
  return false;
}

}  // namespace g2s
