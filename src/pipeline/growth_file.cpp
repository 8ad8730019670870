// Tile growth files: what `g2s grow` hands to `g2s stitch` when the stages run as separate
// processes (or on separate machines sharing the store). One file per tile, written atomically;
// a fixed little-endian header with the store's fingerprint (a growth from another store or
// another version of it is refused), then the triangles, their groups and the suspect corners,
// each part covered by an XXH64 checksum, so a truncated or corrupt file is reported, never
// stitched. docs/pipeline.md gives the layout.
#include <fmt/core.h>

#include <cstring>

#include "g2s/error.hpp"
#include "g2s/pipeline.hpp"
#include "io/le_bytes.hpp"
#include "io/mapped_file.hpp"
#include "tiling/store_format.hpp"
#include "tiling/xxhash64.hpp"

namespace g2s {
namespace {

constexpr char kMagic[8] = {'G', '2', 'S', 'G', 'R', 'O', 'W', '\0'};
// 2: corners as indices into the tile's points; 3: the tile's own non-manifold clean-up counts
// and its final triangles; 4: the options fingerprint.
constexpr std::uint32_t kVersion = 4;
// magic, version, tile, fingerprint, triangles, groups, suspects, points, seeds, spacing,
// duplicates, triangles removed, vertices fixed, final triangles, options fingerprint, payload
// checksum, header checksum. No timings: the same tile gives the same bytes.
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 * 14;
constexpr std::size_t kOptionsAt = 104;
constexpr std::size_t kPayloadChecksumAt = 112;

}  // namespace

std::uint64_t source_fingerprint(const TileSource& source) {
  std::vector<char> bytes;
  auto put = [&](auto value) {
    char buffer[8];
    bytes.insert(bytes.end(), buffer, io::put_le(buffer, value));
  };
  put(static_cast<std::uint64_t>(source.tiles().size()));
  for (const TileInfo& t : source.tiles()) {
    for (int a = 0; a < 3; ++a) put(t.box.lo[a]), put(t.box.hi[a]);
    put(t.points);
    put(t.spacing);
  }
  return tiling::xxhash64(bytes.data(), bytes.size());
}

std::uint64_t options_fingerprint(const PipelineOptions& options) {
  std::vector<char> bytes;
  auto put = [&](auto value) {
    char buffer[8];
    bytes.insert(bytes.end(), buffer, io::put_le(buffer, value));
  };
  const MeshOptions& mesh = options.mesh;
  put(static_cast<std::uint64_t>(mesh.radius_steps.size()));
  for (double step : mesh.radius_steps) put(step);
  put(static_cast<std::uint64_t>(mesh.flatness_levels));
  put(mesh.max_fold_deg);
  put(mesh.max_radius);
  put(mesh.seed_ball);
  put(static_cast<std::uint64_t>(mesh.close_gaps) | static_cast<std::uint64_t>(mesh.orient) << 1);
  put(static_cast<std::uint64_t>(mesh.max_hole_edges));
  put(static_cast<std::uint64_t>(mesh.max_hole_rings));
  put(options.halo_spacings);
  put(options.band_spacings);
  put(static_cast<std::uint64_t>(options.stitch_retries));
  return tiling::xxhash64(bytes.data(), bytes.size());
}

void write_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                       std::uint64_t fingerprint, std::uint64_t options, const TileGrowth& growth) {
  std::vector<char> payload(16 * growth.triangles.size() + 4 * growth.second_fans.size());
  char* p = payload.data();
  for (const Triangle& t : growth.triangles) {
    for (Index v : t) p = io::put_le(p, v);
  }
  for (std::uint32_t g : growth.group) p = io::put_le(p, g);
  for (Index v : growth.second_fans) p = io::put_le(p, v);

  char header[kHeaderBytes];
  std::memcpy(header, kMagic, 8);
  char* h = header + 8;
  h = io::put_le(h, kVersion);
  h = io::put_le(h, tile);
  h = io::put_le(h, fingerprint);
  h = io::put_le(h, static_cast<std::uint64_t>(growth.triangles.size()));
  h = io::put_le(h, static_cast<std::uint64_t>(growth.groups));
  h = io::put_le(h, static_cast<std::uint64_t>(growth.second_fans.size()));
  h = io::put_le(h, growth.report.points);
  h = io::put_le(h, growth.report.seeds);
  h = io::put_le(h, growth.report.spacing);
  h = io::put_le(h, growth.report.duplicates_merged);
  h = io::put_le(h, growth.report.triangles_removed);
  h = io::put_le(h, growth.report.non_manifold_vertices_fixed);
  h = io::put_le(h, static_cast<std::uint64_t>(growth.final_triangles));
  h = io::put_le(h, options);
  h = io::put_le(h, tiling::xxhash64(payload.data(), payload.size()));
  io::put_le(h, tiling::xxhash64(header, kHeaderBytes - 8));

  AtomicFile out(file);
  out.write(header, kHeaderBytes);
  out.write(payload.data(), payload.size());
  out.commit();
}

TileGrowth read_tile_growth(const std::filesystem::path& file, std::uint32_t tile,
                            std::uint64_t fingerprint, std::uint64_t options) {
  auto fail = [&](const std::string& what) {
    return Error(Exit::bad_input, fmt::format("{}: {}", file.string(), what));
  };
  if (!std::filesystem::is_regular_file(file)) {
    throw fail("no tile growth there (was the tile grown?)");
  }
  const io::MappedFile bytes(file);
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.bytes(), kMagic, 8) != 0) {
    throw fail("not a g2s tile growth file (or truncated before its header ends)");
  }
  const unsigned char* h = bytes.bytes();
  if (tiling::load_le<std::uint64_t>(h + kHeaderBytes - 8) !=
      tiling::xxhash64(h, kHeaderBytes - 8)) {
    throw fail("header checksum mismatch (the file is corrupt)");
  }
  const auto version = tiling::load_le<std::uint32_t>(h + 8);
  if (version != kVersion) {
    throw fail(fmt::format("tile growth version {}, this g2s reads {}", version, kVersion));
  }
  if (tiling::load_le<std::uint32_t>(h + 12) != tile) {
    throw fail(fmt::format("holds tile {}, expected tile {}",
                           tiling::load_le<std::uint32_t>(h + 12), tile));
  }
  if (tiling::load_le<std::uint64_t>(h + 16) != fingerprint) {
    throw fail("grown from a different tile store (re-run g2s grow on this store)");
  }
  if (tiling::load_le<std::uint64_t>(h + kOptionsAt) != options) {
    throw Error(Exit::usage,
                fmt::format("{}: grown with other mesh options than these (--radius-steps, "
                            "--flatness-levels, --max-fold, --max-radius, --keep-gaps, "
                            "--no-orient, --max-hole-edges, --max-hole-rings): give the options "
                            "g2s grow was given, or grow again",
                            file.string()));
  }
  const auto triangles = tiling::load_le<std::uint64_t>(h + 24);
  const auto groups = tiling::load_le<std::uint64_t>(h + 32);
  const auto suspects = tiling::load_le<std::uint64_t>(h + 40);
  if (triangles > kNoIndex || suspects > kNoIndex || groups > triangles ||
      bytes.size() - kHeaderBytes != 16 * triangles + 4 * suspects) {
    throw fail(
        fmt::format("{} bytes of triangles and corners, the header says {} triangles and "
                    "{} corners (truncated?)",
                    bytes.size() - kHeaderBytes, triangles, suspects));
  }
  const unsigned char* p = h + kHeaderBytes;
  if (tiling::load_le<std::uint64_t>(h + kPayloadChecksumAt) !=
      tiling::xxhash64(p, bytes.size() - kHeaderBytes)) {
    throw fail("triangle checksum mismatch (the file is corrupt)");
  }
  TileGrowth g;
  g.groups = static_cast<std::uint32_t>(groups);
  g.report.points = tiling::load_le<std::uint64_t>(h + 48);
  g.report.seeds = tiling::load_le<std::uint64_t>(h + 56);
  g.report.spacing = tiling::load_le<double>(h + 64);
  g.report.duplicates_merged = tiling::load_le<std::uint64_t>(h + 72);
  g.report.triangles_removed = tiling::load_le<std::uint64_t>(h + 80);
  g.report.non_manifold_vertices_fixed = tiling::load_le<std::uint64_t>(h + 88);
  g.final_triangles = tiling::load_le<std::uint64_t>(h + 96);
  if (g.final_triangles > triangles) {
    throw fail("more final triangles than triangles (the file is corrupt)");
  }
  g.triangles.resize(triangles);
  for (Triangle& t : g.triangles) {
    for (Index& v : t) {
      v = tiling::load_le<Index>(p), p += 4;
      if (v >= g.report.points)
        throw fail("a triangle corner is out of range (the file is corrupt)");
    }
  }
  g.group.resize(triangles);
  for (std::uint32_t& group : g.group) {
    group = tiling::load_le<std::uint32_t>(p), p += 4;
    if (group >= groups) throw fail("a triangle's group is out of range (the file is corrupt)");
  }
  g.second_fans.resize(suspects);
  for (Index& v : g.second_fans) {
    v = tiling::load_le<Index>(p), p += 4;
    if (v >= g.report.points) throw fail("a suspect corner is out of range (the file is corrupt)");
  }
  g.report.triangles_grown = triangles;
  return g;
}

}  // namespace g2s
