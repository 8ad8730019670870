// ASPRS LAS reader (versions 1.0 to 1.4, point data record formats 0 to 10) behind read_points
// and scan_points. Only what the mesher needs is taken: the scaled integer x, y, z that start
// every record. Real files are trusted only where the specification leaves no choice: the
// records are found at the header's "offset to point data" (never by adding up the VLRs, whose
// count is often wrong), stepped by the header's record length (extra bytes are common), and
// counted by the 64-bit count of LAS 1.4 (the legacy 32-bit count is 0 or stale there for
// formats 6 and up). Scale and offset are applied in double, so georeferenced coordinates reach
// the local-frame path of the pipeline exactly, as a double PLY's do. LAZ is refused with how to
// decompress it: no LAZ library is packaged for Debian bookworm.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string_view>
#include <vector>

#include "io/le_bytes.hpp"
#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s::io {
namespace {

// Offsets in the public header block (LAS 1.4 R15, Table 3; the same in 1.0 to 1.3).
namespace field {
inline constexpr std::size_t version_major = 24;
inline constexpr std::size_t version_minor = 25;
inline constexpr std::size_t header_size = 94;
inline constexpr std::size_t point_offset = 96;
inline constexpr std::size_t vlr_count = 100;
inline constexpr std::size_t point_format = 104;
inline constexpr std::size_t record_length = 105;
inline constexpr std::size_t legacy_count = 107;
inline constexpr std::size_t scale = 131;   // 3 doubles: x, y, z
inline constexpr std::size_t offset = 155;  // 3 doubles: x, y, z
inline constexpr std::size_t count_64 = 247;
}  // namespace field

inline constexpr std::size_t kHeaderSize10 = 227;  // LAS 1.0 to 1.2
inline constexpr std::size_t kHeaderSize13 = 235;  // + start of waveform data
inline constexpr std::size_t kHeaderSize14 = 375;  // + extended VLRs and 64-bit counts
inline constexpr std::size_t kVlrHeaderSize = 54;

// Smallest record of each point data format (the specification's sizes; files may add extra
// bytes after them).
inline constexpr std::uint16_t kMinRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

struct LasHeader {
  unsigned major = 0;
  unsigned minor = 0;
  unsigned format = 0;
  std::size_t point_offset = 0;
  std::size_t record_length = 0;
  std::uint64_t count = 0;
  double scale[3] = {};
  double offset[3] = {};
};

[[noreturn]] void refuse_laz(const MappedFile& file, unsigned format_byte) {
  fail_input(file.name(),
             "a LAZ file (compressed LAS, point format byte 0x{:02x}), which g2s does not read; "
             "decompress it first, e.g. 'laszip -i in.laz -o out.las' (LAStools) or 'pdal "
             "translate in.laz out.las'",
             format_byte);
}

// True when a VLR between the header and the points is LASzip's ("laszip encoded", 22204): a
// compressed file whose format byte lost its compression bit. The walk stops at the points
// whatever the VLR count says.
bool has_laszip_vlr(const MappedFile& file, std::size_t header_size, std::size_t point_offset,
                    std::uint32_t vlr_count) {
  const unsigned char* data = file.bytes();
  std::size_t pos = header_size;
  for (std::uint32_t i = 0; i < vlr_count && pos + kVlrHeaderSize <= point_offset; ++i) {
    const std::string_view user(reinterpret_cast<const char*>(data + pos + 2), 16);
    const auto record_id = get_le<std::uint16_t>(data + pos + 18);
    if (user.substr(0, user.find('\0')) == "laszip encoded" && record_id == 22204) return true;
    pos += kVlrHeaderSize + get_le<std::uint16_t>(data + pos + 20);
  }
  return false;
}

LasHeader parse_las_header(const MappedFile& file) {
  const std::string& name = file.name();
  const unsigned char* data = file.bytes();
  const std::size_t size = file.size();
  if (size < kHeaderSize10) {
    fail_input(name, "byte {}: file ends inside the LAS header (at least {} bytes)", size,
               kHeaderSize10);
  }
  LasHeader h;
  h.major = data[field::version_major];
  h.minor = data[field::version_minor];
  if (h.major != 1 || h.minor > 4) {
    fail_input(name, "byte {}: LAS version {}.{} (expected 1.0 to 1.4)", field::version_major,
               h.major, h.minor);
  }
  const std::size_t header_size = get_le<std::uint16_t>(data + field::header_size);
  const std::size_t needed = h.minor >= 4   ? kHeaderSize14
                             : h.minor == 3 ? kHeaderSize13
                                            : kHeaderSize10;
  if (header_size < needed) {
    fail_input(name, "byte {}: header size {} is smaller than LAS 1.{}'s {} bytes",
               field::header_size, header_size, h.minor, needed);
  }
  if (header_size > size) {
    fail_input(name, "byte {}: file ends inside the LAS header ({} bytes)", size, header_size);
  }
  h.point_offset = get_le<std::uint32_t>(data + field::point_offset);
  if (h.point_offset < header_size) {
    fail_input(name, "byte {}: offset to point data {} is inside the {}-byte header",
               field::point_offset, h.point_offset, header_size);
  }
  if (h.point_offset > size) {
    fail_input(name, "byte {}: offset to point data {} is past the end of the file ({} bytes)",
               field::point_offset, h.point_offset, size);
  }
  const unsigned format_byte = data[field::point_format];
  // LASzip marks compressed records with bit 7 (and older versions bit 6) of the format byte.
  if ((format_byte & 0xC0U) != 0 ||
      has_laszip_vlr(file, header_size, h.point_offset,
                     get_le<std::uint32_t>(data + field::vlr_count))) {
    refuse_laz(file, format_byte);
  }
  h.format = format_byte;
  if (h.format > 10) {
    fail_input(name, "byte {}: point data record format {} (expected 0 to 10)", field::point_format,
               h.format);
  }
  h.record_length = get_le<std::uint16_t>(data + field::record_length);
  if (h.record_length < kMinRecordLength[h.format]) {
    fail_input(name, "byte {}: point record length {} is shorter than point format {}'s {} bytes",
               field::record_length, h.record_length, h.format, kMinRecordLength[h.format]);
  }
  // LAS 1.4 counts in 64 bits; its legacy 32-bit count must be 0 for formats 6 and up and is
  // often stale, so it only stands in when the 64-bit count is missing (a 1.2-style writer).
  h.count = get_le<std::uint32_t>(data + field::legacy_count);
  if (h.minor >= 4) {
    const auto count_64 = get_le<std::uint64_t>(data + field::count_64);
    if (count_64 != 0) h.count = count_64;
  }
  static constexpr char kAxes[3] = {'x', 'y', 'z'};
  for (std::size_t a = 0; a < 3; ++a) {
    h.scale[a] = get_le<double>(data + field::scale + 8 * a);
    h.offset[a] = get_le<double>(data + field::offset + 8 * a);
    if (!std::isfinite(h.scale[a]) || h.scale[a] == 0.0) {
      fail_input(name, "byte {}: {} scale factor {} (expected a finite non-zero number)",
                 field::scale + 8 * a, kAxes[a], h.scale[a]);
    }
    if (!std::isfinite(h.offset[a])) {
      fail_input(name, "byte {}: {} offset {} (expected a finite number)", field::offset + 8 * a,
                 kAxes[a], h.offset[a]);
    }
  }
  const std::uint64_t fit = (size - h.point_offset) / h.record_length;
  if (fit < h.count) {
    fail_input(name,
               "byte {}: file ends inside point {} of {} (the header declares {} records of {} "
               "bytes from byte {}; truncated body?)",
               size, fit + 1, h.count, h.count, h.record_length, h.point_offset);
  }
  return h;
}

// Converts `count` records from `base` into out (x, y, z); returns the finite points kept.
std::size_t convert_records(const unsigned char* base, std::size_t stride, std::size_t count,
                            const LasHeader& h, double* out, std::uint64_t& non_finite) {
  std::size_t kept = 0;
  for (std::size_t r = 0; r < count; ++r) {
    const unsigned char* record = base + r * stride;
    double* o = out + 3 * kept;
    for (std::size_t a = 0; a < 3; ++a) {
      o[a] = static_cast<double>(get_le<std::int32_t>(record + 4 * a)) * h.scale[a] + h.offset[a];
    }
    // Finite scale and offset can still overflow (a scale of 1e300).
    if (std::isfinite(o[0]) && std::isfinite(o[1]) && std::isfinite(o[2])) {
      ++kept;
    } else {
      ++non_finite;
    }
  }
  return kept;
}

}  // namespace

PointCloud read_las_points(const MappedFile& file, ReadReport& report, const RunSink* sink) {
  const LasHeader h = parse_las_header(file);
  report.format = fmt::format("las-1.{}-format{}", h.minor, h.format);
  report.declared = h.count;
  const std::size_t run = sink != nullptr
                              ? kScanChunkPoints
                              : static_cast<std::size_t>(std::max<std::uint64_t>(h.count, 1));
  PointCloud cloud;
  std::vector<double>& xyz = cloud.xyz;
  for (std::uint64_t first = 0; first < h.count; first += run) {
    const auto rows = static_cast<std::size_t>(std::min<std::uint64_t>(run, h.count - first));
    const std::size_t begin = h.point_offset + static_cast<std::size_t>(first) * h.record_length;
    xyz.resize(rows * 3);
    const std::size_t kept = convert_records(file.bytes() + begin, h.record_length, rows, h,
                                             xyz.data(), report.non_finite);
    xyz.resize(kept * 3);
    report.points += kept;
    if (sink != nullptr) {
      if (!xyz.empty()) (*sink)(xyz);
      xyz.clear();
      file.release_before(begin + rows * h.record_length);
    }
  }
  return cloud;
}

}  // namespace g2s::io
