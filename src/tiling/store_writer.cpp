// build_tile_store (docs/tile-store.md): tiles a cloud in streaming passes
// with bounded memory. Pass 1 finds the bounding box and a deterministic sample; the box is
// split k-d style at box midpoints or sample quantiles (tile_split.hpp); when the sample did
// not hold every point, counting passes check the tiles and re-split any over budget. Then the
// blocks are written in rounds of consecutive tiles holding at most round_points points. One
// round takes its points from one more pass over the input; several take them from a spill
// file that one pass has scattered every point to, in per-tile runs. Points are taken in input
// order, sorted by a total order, and frames encoded in parallel but written in order, so the
// bytes do not depend on round_points, threads or timing.
#include <fcntl.h>
#include <fmt/core.h>
#include <sys/stat.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/surface_check.hpp"
#include "g2s/tile_store.hpp"
#include "io/readers.hpp"
#include "io/write_behind.hpp"
#include "tiling/store_format.hpp"
#include "tiling/tile_geometry.hpp"
#include "tiling/tile_spacing.hpp"
#include "tiling/tile_split.hpp"
#include "tiling/xxhash64.hpp"

namespace g2s {
namespace {

using namespace tiling;

// Pass 1 holds up to twice this many sample points (32 bytes each: 17 MB); a cloud of at most
// twice as many points is sampled whole, so its tiles are exact without a counting pass.
constexpr std::size_t kSampleTarget = std::size_t{1} << 18;
// A tile split on a partial sample aims this far below the budget, so that the counting pass
// rarely finds one over it.
constexpr double kSampledTargetFraction = 0.75;
// The spill pass's per-tile buffers share this much, or the round's points' worth if less (the
// writer's memory bound; one point a tile at least, which is less than the tile's table entry):
// 124 KB a tile for the 258 tiles of 160M points under --memory 1G, so each write moves over
// 100 KB at once, and freed before the rounds allocate theirs.
constexpr std::size_t kSpillBufferBytes = std::size_t{32} << 20;

// Streams the finite points of the input with their global ids; returns the reader's report.
template <class Visit>
ReadReport for_each_point(const std::filesystem::path& input, Visit&& visit) {
  ReadReport report;
  std::uint64_t id = 0;
  io::scan_points_ahead(
      input,
      [&](std::span<const double> xyz) {
        for (std::size_t i = 0; i < xyz.size(); i += 3) visit(&xyz[i], id++);
      },
      report);
  return report;
}

[[noreturn]] void throw_changed(const std::filesystem::path& input) {
  throw Error(Exit::bad_input,
              fmt::format("{}: the file changed while it was being tiled", input.string()));
}

// A later pass must see the cloud the first one saw.
void check_unchanged(const std::filesystem::path& input, const ReadReport& first,
                     const ReadReport& again) {
  if (again.points != first.points || again.non_finite != first.non_finite) throw_changed(input);
}

// Exact point count of every leaf (indexed by node).
std::vector<std::uint64_t> count_leaves(const std::filesystem::path& input, const TileTree& tree,
                                        const ReadReport& first) {
  std::vector<std::uint64_t> counts(tree.node_count(), 0);
  const ReadReport again =
      for_each_point(input, [&](const double* p, std::uint64_t) { ++counts[tree.leaf_of(p)]; });
  check_unchanged(input, first, again);
  return counts;
}

// Builds the tree and returns the exact point count of every node (leaves only are set).
std::vector<std::uint64_t> split_into_tiles(const std::filesystem::path& input, TileTree& tree,
                                            const PointSample& first_sample,
                                            const ReadReport& first, std::uint64_t budget) {
  const double sampled_target = static_cast<double>(budget) * kSampledTargetFraction;
  const double smallest = kLastTileShare * static_cast<double>(budget);
  if (first_sample.holds_every_point()) {
    tree.split(0, first_sample, 1.0, static_cast<double>(budget));
    tree.taper(first_sample, 1.0, smallest);
    std::vector<std::uint64_t> counts(tree.node_count(), 0);
    for (std::size_t i = 0; i < first_sample.size(); ++i) {
      ++counts[tree.leaf_of(first_sample.point(i))];
    }
    return counts;
  }
  const double first_weight =
      static_cast<double>(first.points) / static_cast<double>(first_sample.size());
  tree.split(0, first_sample, first_weight, sampled_target);
  tree.taper(first_sample, first_weight, smallest);
  for (;;) {
    std::vector<std::uint64_t> counts = count_leaves(input, tree, first);
    std::vector<std::uint32_t> over;
    for (std::uint32_t n = 0; n < tree.node_count(); ++n) {
      if (tree.is_leaf(n) && counts[n] > budget) over.push_back(n);
    }
    if (over.empty()) return counts;
    // A sample of each tile over budget, sharing the sample memory of pass 1.
    std::vector<std::uint32_t> slot(tree.node_count(), kNoIndex);
    std::vector<PointSample> samples;
    const std::size_t per_tile = std::max<std::size_t>(kSampleTarget / over.size(), 64);
    for (std::uint32_t i = 0; i < over.size(); ++i) {
      slot[over[i]] = i;
      samples.emplace_back(per_tile);
    }
    const ReadReport again = for_each_point(input, [&](const double* p, std::uint64_t id) {
      const std::uint32_t s = slot[tree.leaf_of(p)];
      if (s != kNoIndex) samples[s].add(p, id);
    });
    check_unchanged(input, first, again);
    bool split_any = false;
    for (std::uint32_t i = 0; i < over.size(); ++i) {
      const PointSample& s = samples[i];
      const bool exact = s.holds_every_point();
      const double weight =
          exact ? 1.0 : static_cast<double>(counts[over[i]]) / static_cast<double>(s.size());
      split_any |=
          tree.split(over[i], s, weight, exact ? static_cast<double>(budget) : sampled_target);
    }
    // Only tiles of coinciding points are left over budget: no plane separates them.
    if (!split_any) return counts;
  }
}

// Beyond one round, the points in tile order (x, y, z of every point, then every id; a tile's
// points in input order), so that a round reads its consecutive tiles back in two reads rather
// than the whole input. Beside the store, and unlinked as soon as it is open: the kernel frees
// it when it is closed, however the process ends (even killed).
class SpillFile {
 public:
  SpillFile(const AtomicFile& store, std::uint64_t bytes)
      : target_(store.target()), path_(store.temporary().string() + ".spill") {
    fd_ = ::open(path_.path().c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd_ < 0) fail("cannot create the spill file");
    ::unlink(path_.path().c_str());
    // Reserved up front, so a full disk fails now rather than a pass later (where the
    // filesystem cannot reserve, at the write that does not fit).
    if (::fallocate(fd_, 0, 0, static_cast<off_t>(bytes)) != 0 && errno != EOPNOTSUPP) {
      const int err = errno;
      ::close(fd_);  // no destructor runs after a constructor throws
      fail("cannot write the spill file", err);
    }
  }
  ~SpillFile() {
    behind_.reset();  // the write in flight first
    ::close(fd_);
  }
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  // From now on, write_behind_at hands writes of up to `capacity` bytes to a thread of its own,
  // so that the pass fills its buffers while the kernel copies the last one.
  void write_behind(std::size_t capacity) {
    behind_ = std::make_unique<WriteBehind>(fd_, capacity);
    staging_.reserve(capacity);
  }
  void write_behind_at(std::uint64_t offset, const void* data, std::size_t bytes) {
    const char* p = static_cast<const char*>(data);
    staging_.assign(p, p + bytes);
    if (const int err = behind_->submit(staging_, offset); err != 0) {
      fail("cannot write the spill file", err);
    }
  }
  // Waits until every write handed over is done.
  void wait_written() {
    if (const int err = behind_ ? behind_->wait() : 0; err != 0) {
      fail("cannot write the spill file", err);
    }
  }
  void read_at(std::uint64_t offset, void* data, std::size_t bytes) const {
    whole(::pread, static_cast<char*>(data), bytes, offset, "cannot read back the spill file");
  }

 private:
  // Calls pwrite or pread until all `bytes` are done (they may do less, or be interrupted).
  template <class Call, class Byte>
  void whole(Call call, Byte* p, std::size_t bytes, std::uint64_t offset, const char* what) const {
    while (bytes > 0) {
      const ssize_t n = call(fd_, p, bytes, static_cast<off_t>(offset));
      if (n < 0 && errno == EINTR) continue;
      if (n == 0) errno = EIO;
      if (n <= 0) fail(what);
      p += n;
      bytes -= static_cast<std::size_t>(n);
      offset += static_cast<std::uint64_t>(n);
    }
  }
  [[noreturn]] void fail(const char* what, int err = errno) const {
    throw Error(Exit::write_failed,
                fmt::format("{}: {}: {}", target_.string(), what, std::strerror(err)));
  }

  std::filesystem::path target_;
  TemporaryPath path_;  // removes the name should a signal come before the unlink
  int fd_ = -1;
  std::unique_ptr<WriteBehind> behind_;
  std::vector<char> staging_;  // the next write's bytes
};

// The spill pass: each point goes to its tile's buffer, and a full buffer to the tile's run at
// the tile's running offset. `tile_start` holds each tile's first point in tile order, then the
// total.
void spill_points(const std::filesystem::path& input, const TileTree& tree,
                  std::span<const std::uint32_t> tile_of_node,
                  std::span<const std::uint64_t> tile_start, std::uint64_t round_points,
                  const ReadReport& report, SpillFile& spill) {
  const std::size_t tiles = tile_start.size() - 1;
  const std::uint64_t ids_offset = 3 * sizeof(double) * tile_start[tiles];
  const std::size_t shared = std::min<std::uint64_t>(kSpillBufferBytes, kPointBytes * round_points);
  const std::size_t per_tile = std::max<std::size_t>(shared / (kPointBytes * tiles), 1);
  std::vector<double> xyz(3 * per_tile * tiles);
  std::vector<Index> ids(per_tile * tiles);
  std::vector<std::uint64_t> flushed(tile_start.begin(), tile_start.end() - 1);  // in tile order
  std::vector<std::size_t> held(tiles, 0);
  spill.write_behind(3 * sizeof(double) * per_tile);
  const auto flush = [&](std::size_t t) {
    spill.write_behind_at(3 * sizeof(double) * flushed[t], &xyz[3 * per_tile * t],
                          3 * sizeof(double) * held[t]);
    spill.write_behind_at(ids_offset + sizeof(Index) * flushed[t], &ids[per_tile * t],
                          sizeof(Index) * held[t]);
    flushed[t] += held[t];
    held[t] = 0;
  };
  const ReadReport again = for_each_point(input, [&](const double* p, std::uint64_t id) {
    const std::uint32_t t = tile_of_node[tree.leaf_of(p)];
    if (flushed[t] + held[t] == tile_start[t + 1]) throw_changed(input);  // before overrunning
    const std::size_t at = per_tile * t + held[t];
    std::copy_n(p, 3, &xyz[3 * at]);
    ids[at] = static_cast<Index>(id);
    if (++held[t] == per_tile) flush(t);
  });
  check_unchanged(input, report, again);
  for (std::size_t t = 0; t < tiles; ++t) flush(t);
  spill.wait_written();
}

struct BlockEntry {
  std::uint64_t offset = 0;
  std::uint64_t bytes = 0;
  std::uint64_t frame_table_checksum = 0;
};

// What a thread needs to encode frames: the decoded bytes and a zstd context, reused.
struct FrameEncoder {
  std::vector<unsigned char> raw;
  ZSTD_CCtx* zstd = ZSTD_createCCtx();
  FrameEncoder() = default;
  FrameEncoder(const FrameEncoder&) : FrameEncoder() {}  // copies start fresh (TBB's exemplar)
  FrameEncoder& operator=(const FrameEncoder&) = delete;
  ~FrameEncoder() { ZSTD_freeCCtx(zstd); }
};

// Scratch buffers reused for every block.
struct BlockScratch {
  std::vector<std::pair<double, std::uint32_t>> order;
  std::vector<std::pair<double, std::uint32_t>> sorted;  // sort_by_distance's buffer
  std::vector<unsigned char> frame_table;
  std::vector<std::vector<unsigned char>> frames;  // each frame's stored bytes
  std::vector<std::size_t> zstd_results;           // each frame's zstd return code
  tbb::enumerable_thread_specific<FrameEncoder> encoders;
};

// Sorts (distance, local index) pairs as std::sort would, by distance, then index. They come in
// index order, so a stable sort by distance alone gives that order: a radix sort on keys that
// order as the distances do (a comparison sort of a tile's points was a fifth of the tile store's
// time). Distances are never NaN.
void sort_by_distance(std::vector<std::pair<double, std::uint32_t>>& order,
                      std::vector<std::pair<double, std::uint32_t>>& buffer) {
  constexpr int kDigitBits = 16;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  // The bits of a non-negative double order as unsigned integers; a negative one's, flipped,
  // order below them. -0.0 is taken as +0.0, which it equals.
  const auto key = [](const std::pair<double, std::uint32_t>& e) {
    const auto bits = std::bit_cast<std::uint64_t>(e.first + 0.0);
    return bits >> 63 ? ~bits : bits | std::uint64_t{1} << 63;
  };
  buffer.resize(order.size());
  std::vector<std::uint32_t> count(kBuckets);
  for (int shift = 0; shift < 64; shift += kDigitBits) {
    std::fill(count.begin(), count.end(), 0);
    for (const auto& e : order) ++count[key(e) >> shift & (kBuckets - 1)];
    // A digit all keys share leaves the order as it is.
    if (std::find(count.begin(), count.end(), order.size()) != count.end()) continue;
    std::uint32_t at = 0;
    for (std::uint32_t& c : count) at += std::exchange(c, at);
    for (const auto& e : order) buffer[count[key(e) >> shift & (kBuckets - 1)]++] = e;
    order.swap(buffer);
  }
}

// Encodes one frame, the points `order` picks, into `stored` (compressed if asked); returns
// zstd's result (an error code to check) or the raw size.
std::size_t encode_frame(std::span<const double> xyz, std::span<const Index> ids,
                         std::span<const std::pair<double, std::uint32_t>> order,
                         const TileStoreOptions& options, FrameEncoder& encoder,
                         std::vector<unsigned char>& stored) {
  const std::size_t m = order.size();
  std::vector<unsigned char>& raw = options.compress ? encoder.raw : stored;
  raw.resize(m * kPointBytes);
  unsigned char* out = raw.data();
  for (std::size_t k = 0; k < m; ++k) {
    const double* p = &xyz[3 * order[k].second];
    for (int a = 0; a < 3; ++a) store_le(out + (3 * k + a) * sizeof(double), p[a]);
  }
  out += 3 * m * sizeof(double);
  for (std::size_t k = 0; k < m; ++k) store_le(out + k * sizeof(Index), ids[order[k].second]);
  if (!options.compress) return raw.size();
  stored.resize(ZSTD_compressBound(raw.size()));
  const std::size_t result = ZSTD_compressCCtx(encoder.zstd, stored.data(), stored.size(),
                                               raw.data(), raw.size(), options.zstd_level);
  stored.resize(ZSTD_isError(result) ? 0 : result);
  return result;
}

// Writes one tile's block: its frame table, then its points ordered by border distance (ties
// by id) in frames of kFramePoints, raw or zstd-compressed. The frames are encoded in parallel
// into their own buffers and written in order, so the bytes do not depend on the threads.
BlockEntry write_block(AtomicFile& file, std::span<const double> xyz, std::span<const Index> ids,
                       const TileBox& box, const TileBox& bounds, const TileStoreOptions& options,
                       BlockScratch& scratch) {
  const std::size_t n = ids.size();
  const BorderFaces faces(box, bounds);
  // (distance, local index) pairs: the points came in id order, so the index breaks ties as
  // the id would, and the pairs sort without chasing pointers.
  scratch.order.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    scratch.order[i] = {faces.distance(&xyz[3 * i]), static_cast<std::uint32_t>(i)};
  }
  sort_by_distance(scratch.order, scratch.sorted);

  const std::size_t frames = frame_count(n, kFramePoints);
  scratch.frames.resize(std::max(scratch.frames.size(), frames));
  scratch.zstd_results.resize(frames);
  tbb::parallel_for(std::size_t{0}, frames, [&](std::size_t f) {
    const std::size_t first = f * kFramePoints;
    const std::size_t m = std::min<std::size_t>(kFramePoints, n - first);
    scratch.zstd_results[f] = encode_frame(xyz, ids, std::span(scratch.order).subspan(first, m),
                                           options, scratch.encoders.local(), scratch.frames[f]);
  });

  BlockEntry entry;
  entry.offset = file.size();
  scratch.frame_table.assign(frames * kFrameEntryBytes, 0);
  std::uint64_t offset = scratch.frame_table.size();
  for (std::size_t f = 0; f < frames; ++f) {
    if (ZSTD_isError(scratch.zstd_results[f])) {
      throw Error(Exit::failure,
                  fmt::format("{}: zstd compression failed: {}", file.target().string(),
                              ZSTD_getErrorName(scratch.zstd_results[f])));
    }
    const std::vector<unsigned char>& stored = scratch.frames[f];
    unsigned char* e = scratch.frame_table.data() + f * kFrameEntryBytes;
    store_le(e + frame::offset, offset);
    store_le(e + frame::stored_bytes, std::uint64_t{stored.size()});
    store_le(e + frame::first_distance, scratch.order[f * kFramePoints].first);
    store_le(e + frame::checksum, xxhash64(stored.data(), stored.size()));
    offset += stored.size();
  }
  file.write(scratch.frame_table.data(), scratch.frame_table.size());
  for (std::size_t f = 0; f < frames; ++f)
    file.write(scratch.frames[f].data(), scratch.frames[f].size());
  entry.bytes = file.size() - entry.offset;
  entry.frame_table_checksum = xxhash64(scratch.frame_table.data(), scratch.frame_table.size());
  return entry;
}

}  // namespace

StoreOrigin store_origin(const std::filesystem::path& input, std::uint64_t tile_points) {
  const io::MappedFile file(input, io::MapMode::random);
  StoreOrigin origin;
  origin.bytes = file.size();
  origin.tile_points = tile_points;
  struct stat st {};
  if (::stat(input.c_str(), &st) == 0) {
    origin.mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000 +
                      static_cast<std::int64_t>(st.st_mtim.tv_nsec);
  }
  constexpr std::size_t kMiB = std::size_t{1} << 20;
  const std::size_t head = std::min(file.size(), kMiB);
  const std::size_t tail_begin = file.size() - std::min(file.size(), kMiB);
  std::uint64_t parts[3] = {xxhash64(file.bytes(), head),
                            xxhash64(file.bytes() + tail_begin, file.size() - tail_begin),
                            file.size()};
  origin.content = xxhash64(parts, sizeof parts);
  file.release(0, file.size());
  std::error_code ec;
  const std::string absolute = std::filesystem::absolute(input, ec).lexically_normal().string();
  origin.path = xxhash64(absolute.data(), absolute.size());
  return origin;
}

TileStoreReport build_tile_store(const std::filesystem::path& input,
                                 const std::filesystem::path& store,
                                 const TileStoreOptions& options) {
  if (options.tile_points == 0) throw Error(Exit::usage, "tile points must be at least 1");
  std::error_code ec;
  const auto status = std::filesystem::status(input, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status) &&
      !std::filesystem::is_directory(status)) {
    throw Error(Exit::bad_input,
                fmt::format("{}: not a regular file (tiling reads its input several times, so a "
                            "pipe or device cannot be tiled)",
                            input.string()));
  }

  const StoreOrigin origin = store_origin(input, options.tile_points);

  // Pass 1: bounding box and sample.
  TileBox bounds;
  for (int a = 0; a < 3; ++a) {
    bounds.lo[a] = std::numeric_limits<double>::infinity();
    bounds.hi[a] = -std::numeric_limits<double>::infinity();
  }
  PointSample sample(kSampleTarget);
  double extreme[6][3] = {};  // the first point to reach each bound: lo x, hi x, lo y, ...
  const ReadReport first = for_each_point(input, [&](const double* p, std::uint64_t id) {
    for (int a = 0; a < 3; ++a) {
      if (p[a] < bounds.lo[a]) std::copy_n(p, 3, extreme[2 * a]);
      if (p[a] > bounds.hi[a]) std::copy_n(p, 3, extreme[2 * a + 1]);
      bounds.lo[a] = std::min(bounds.lo[a], p[a]);
      bounds.hi[a] = std::max(bounds.hi[a], p[a]);
    }
    sample.add(p, id);
  });
  if (!sample.holds_every_point()) {
    for (const double* p : extreme) sample.add_always(p);
  }
  if (first.points > kNoIndex) {
    throw Error(Exit::bad_input,
                fmt::format("{}: {} points; the tile store numbers points with 32 bits (at most "
                            "{})",
                            input.string(), first.points, kNoIndex));
  }
  if (first.points == 0) bounds = TileBox{};
  if (const std::string why = why_beyond_float(bounds.lo, bounds.hi); !why.empty()) {
    throw Error(Exit::no_surface, fmt::format("{}: no surface can be formed: {}; nothing written",
                                              input.string(), why));
  }
  const std::uint64_t total = first.points;
  if (options.progress) options.progress(0, total);

  const std::uint64_t tile_points = largest_tile_points(options, total);
  TileTree tree(bounds);
  std::vector<std::uint64_t> counts;
  std::vector<std::uint32_t> leaves;
  if (total > 0) {
    counts = split_into_tiles(input, tree, sample, first, tile_points);
    leaves = tree.leaves();
  }
  sample = PointSample(0);  // its memory is not needed while writing
  const std::size_t tiles = leaves.size();
  std::vector<std::uint32_t> tile_of_node(tree.node_count(), kNoIndex);
  for (std::uint32_t t = 0; t < tiles; ++t) tile_of_node[leaves[t]] = t;

  AtomicFile file(store);
  file.write_behind();
  std::vector<unsigned char> header(kHeaderBytes, 0);
  std::vector<unsigned char> table(tiles * kEntryBytes, 0);
  file.write(header.data(), header.size());
  file.write(table.data(), table.size());

  // Rounds: runs of consecutive tiles holding at most round_points points (at least one tile).
  // The point buffers are sized once for the largest, so they never reallocate (a copy would
  // double the peak).
  const std::uint64_t round_points = std::max(options.round_points, options.tile_points);
  std::vector<std::uint64_t> tile_start(tiles + 1, 0);  // each tile's first point in tile order
  std::vector<std::size_t> round_first = {0};
  std::uint64_t largest_round = 0;
  for (std::size_t t = 0; t < tiles; ++t) {
    tile_start[t + 1] = tile_start[t] + counts[leaves[t]];
    const std::uint64_t base = tile_start[round_first.back()];
    if (tile_start[t] > base && tile_start[t + 1] - base > round_points) round_first.push_back(t);
    largest_round = std::max(largest_round, tile_start[t + 1] - tile_start[round_first.back()]);
  }
  round_first.push_back(tiles);

  // One round reads its points from the input; several read theirs from the spill file, which
  // one pass fills (its buffers are freed before the rounds' are allocated).
  std::unique_ptr<SpillFile> spill;
  if (round_first.size() > 2) {
    spill = std::make_unique<SpillFile>(file, kPointBytes * total);
    spill_points(input, tree, tile_of_node, tile_start, round_points, first, *spill);
  }

  BlockScratch scratch;
  std::vector<NearestThree> cloud_sample;
  // A round's points: the spill's reads or the pass fill them whole, so they are not cleared
  // first (a pass over 28 bytes a point, 224 MB at the default round).
  const auto xyz = std::make_unique_for_overwrite<double[]>(largest_round * 3);
  const auto ids = std::make_unique_for_overwrite<Index[]>(largest_round);
  std::uint64_t written = 0;
  for (std::size_t round = 0; round + 1 < round_first.size(); ++round) {
    const std::size_t round_begin = round_first[round];
    const std::size_t round_end = round_first[round + 1];
    const std::uint64_t base = tile_start[round_begin];  // the round's first point in tile order
    if (spill) {
      const std::size_t n = tile_start[round_end] - base;
      spill->read_at(3 * sizeof(double) * base, xyz.get(), 3 * sizeof(double) * n);
      spill->read_at(3 * sizeof(double) * total + sizeof(Index) * base, ids.get(),
                     sizeof(Index) * n);
    } else {
      std::vector<std::uint64_t> cursor(tile_start.begin() + round_begin,
                                        tile_start.begin() + round_end);
      const ReadReport again = for_each_point(input, [&](const double* p, std::uint64_t id) {
        const std::uint32_t t = tile_of_node[tree.leaf_of(p)];
        if (t < round_begin || t >= round_end) return;
        const std::uint64_t at = cursor[t - round_begin]++;
        if (at == tile_start[t + 1]) throw_changed(input);  // before overrunning
        std::copy_n(p, 3, &xyz[3 * (at - base)]);
        ids[at - base] = static_cast<Index>(id);
      });
      check_unchanged(input, first, again);
    }
    // The spacing estimates of the round's tiles, in parallel (each is a serial pass over its
    // tile); the blocks are then written one by one, each encoded in parallel.
    std::vector<TileSpacing> spacing(round_end - round_begin);
    tbb::parallel_for(round_begin, round_end, [&](std::size_t t) {
      const std::size_t begin = tile_start[t] - base, n = counts[leaves[t]];
      spacing[t - round_begin] = measure_tile_spacing(
          std::span<const double>(xyz.get() + 3 * begin, 3 * n),
          std::span<const Index>(ids.get() + begin, n), tree.box(leaves[t]), bounds, total);
    });
    for (const TileSpacing& s : spacing) {
      cloud_sample.insert(cloud_sample.end(), s.cloud_sample.begin(), s.cloud_sample.end());
    }
    for (std::size_t t = round_begin; t < round_end; ++t) {
      const std::uint32_t node = leaves[t];
      const std::size_t begin = tile_start[t] - base;
      const std::size_t n = counts[node];
      const std::span<const double> tile_xyz(xyz.get() + 3 * begin, 3 * n);
      const BlockEntry block =
          write_block(file, tile_xyz, std::span<const Index>(ids.get() + begin, n), tree.box(node),
                      bounds, options, scratch);
      unsigned char* e = table.data() + t * kEntryBytes;
      const TileBox own = points_box(tile_xyz, tree.box(node));
      for (int a = 0; a < 3; ++a) {
        store_le(e + entry::box + 8 * a, tree.box(node).lo[a]);
        store_le(e + entry::box + 24 + 8 * a, tree.box(node).hi[a]);
        store_le(e + entry::points_box + 8 * a, own.lo[a]);
        store_le(e + entry::points_box + 24 + 8 * a, own.hi[a]);
      }
      store_le(e + entry::points, std::uint64_t{n});
      store_le(e + entry::spacing, spacing[t - round_begin].mean);
      store_le(e + entry::block_offset, block.offset);
      store_le(e + entry::block_bytes, block.bytes);
      store_le(e + entry::frame_table_checksum, block.frame_table_checksum);
      written += n;
      if (options.progress) options.progress(written, total);
    }
  }

  unsigned char* h = header.data();
  std::memcpy(h + header::magic, kMagic, sizeof kMagic);
  store_le(h + header::version, kVersion);
  store_le(h + header::header_bytes, static_cast<std::uint32_t>(kHeaderBytes));
  store_le(h + header::flags, options.compress ? kFlagCompressed : std::uint32_t{0});
  store_le(h + header::frame_points, kFramePoints);
  store_le(h + header::point_count, total);
  store_le(h + header::tile_count, std::uint64_t{tiles});
  for (int a = 0; a < 3; ++a) {
    store_le(h + header::bounds + 8 * a, bounds.lo[a]);
    store_le(h + header::bounds + 24 + 8 * a, bounds.hi[a]);
  }
  store_le(h + header::input_declared, first.declared);
  store_le(h + header::input_points, first.points);
  store_le(h + header::input_non_finite, first.non_finite);
  // A fixed-width field, zero-padded by the header's initialisation: not a C string.
  // NOLINTNEXTLINE(bugprone-not-null-terminated-result)
  std::memcpy(h + header::input_format, first.format.data(),
              std::min(first.format.size(), kFormatChars - 1));
  store_le(h + header::table_offset, std::uint64_t{kHeaderBytes});
  store_le(h + header::table_bytes, std::uint64_t{table.size()});
  store_le(h + header::file_bytes, file.size());
  store_le(h + header::table_checksum, xxhash64(table.data(), table.size()));
  store_le(h + header::origin_bytes, origin.bytes);
  store_le(h + header::origin_mtime, origin.mtime_ns);
  store_le(h + header::origin_content, origin.content);
  store_le(h + header::origin_path, origin.path);
  store_le(h + header::origin_tile_points, origin.tile_points);
  const CloudSpacing spacing = cloud_spacing(cloud_sample);
  store_le(h + header::cloud_spacing, spacing.spacing);
  store_le(h + header::twin_distance, spacing.twin_distance);
  store_le(h + header::group_distance, spacing.group_distance);
  store_le(h + header::header_checksum, xxhash64(h, header::header_checksum));
  file.write_at(0, header.data(), header.size());
  file.write_at(kHeaderBytes, table.data(), table.size());
  TileStoreReport report;
  report.read = first;
  report.tiles = tiles;
  report.bytes = file.size();
  file.commit();
  return report;
}

}  // namespace g2s
