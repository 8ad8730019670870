// Test support: hand-made ASPRS LAS files with every field under the test's control, including
// the ones real writers get wrong (VLR count, legacy count, record length, compression bit). The
// records' bytes after x, y, z are filled with a pattern so a reader that steps by the format's
// size instead of the header's record length reads garbage.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace g2s::test_support {

struct LasSpec {
  unsigned minor = 2;               // LAS 1.minor
  unsigned format = 0;              // point data record format 0-10
  std::uint8_t format_flags = 0;    // or-ed into the format byte (0x80: LASzip's compression bit)
  std::uint16_t extra_bytes = 0;    // after each record's standard fields
  std::uint16_t record_length = 0;  // 0: the format's size + extra_bytes
  // VLRs actually written (payload sizes), and the count the header claims (-1: the truth).
  std::vector<std::uint16_t> vlr_payloads;
  std::int64_t vlr_count_field = -1;
  std::string vlr_user = "g2s-test";  // user id of every VLR ("laszip encoded" for LAZ)
  std::uint16_t vlr_record_id = 1;
  std::uint32_t padding = 0;  // bytes between the VLRs and the points
  // Counts the header claims (-1: the points written; for LAS 1.4 formats 6-10 the legacy count
  // defaults to 0 as the specification asks).
  std::int64_t legacy_count = -1;
  std::int64_t count_64 = -1;
  std::int64_t point_offset = -1;  // -1: right after the VLRs and padding
  std::uint16_t header_size = 0;   // 0: the version's size
  double scale[3] = {0.01, 0.01, 0.01};
  double offset[3] = {0.0, 0.0, 0.0};
  std::size_t drop_tail_bytes = 0;  // cut from the end of the file
};

inline constexpr std::uint16_t kLasRecordSize[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

template <typename T>
void las_put(std::string& out, std::size_t at, T value) {
  std::memcpy(out.data() + at, &value, sizeof value);  // tests run on little-endian hosts
}

// The file's bytes: header, VLRs, padding, then one record per point of `xyz` (integers, before
// scale and offset).
inline std::string las_bytes(const LasSpec& spec,
                             const std::vector<std::array<std::int32_t, 3>>& xyz) {
  const std::uint16_t header_size = spec.header_size  ? spec.header_size
                                    : spec.minor >= 4 ? 375
                                    : spec.minor == 3 ? 235
                                                      : 227;
  const std::uint16_t record_length =
      spec.record_length
          ? spec.record_length
          : static_cast<std::uint16_t>(kLasRecordSize[spec.format] + spec.extra_bytes);
  std::string out(std::max<std::size_t>(header_size, 375), '\0');
  out.resize(header_size);
  std::memcpy(out.data(), "LASF", 4);
  out[24] = 1;
  out[25] = static_cast<char>(spec.minor);
  std::memcpy(out.data() + 26, "g2s test writer", 15);
  las_put<std::uint16_t>(out, 94, header_size);
  std::string vlrs;
  for (std::uint16_t payload : spec.vlr_payloads) {
    std::string vlr(54 + payload, '\x5a');
    las_put<std::uint16_t>(vlr, 0, 0);
    std::memset(vlr.data() + 2, 0, 16);
    std::memcpy(vlr.data() + 2, spec.vlr_user.data(),
                std::min<std::size_t>(spec.vlr_user.size(), 16));
    las_put<std::uint16_t>(vlr, 18, spec.vlr_record_id);
    las_put<std::uint16_t>(vlr, 20, payload);
    vlrs += vlr;
  }
  const std::size_t offset = spec.point_offset >= 0 ? static_cast<std::size_t>(spec.point_offset)
                                                    : header_size + vlrs.size() + spec.padding;
  las_put<std::uint32_t>(out, 96, static_cast<std::uint32_t>(offset));
  las_put<std::uint32_t>(
      out, 100,
      static_cast<std::uint32_t>(spec.vlr_count_field >= 0
                                     ? spec.vlr_count_field
                                     : static_cast<std::int64_t>(spec.vlr_payloads.size())));
  out[104] = static_cast<char>(spec.format | spec.format_flags);
  las_put<std::uint16_t>(out, 105, record_length);
  const auto n = static_cast<std::int64_t>(xyz.size());
  const std::int64_t legacy =
      spec.legacy_count >= 0 ? spec.legacy_count : (spec.minor >= 4 && spec.format >= 6 ? 0 : n);
  las_put<std::uint32_t>(out, 107, static_cast<std::uint32_t>(legacy));
  for (int a = 0; a < 3; ++a) {
    las_put<double>(out, 131 + 8 * a, spec.scale[a]);
    las_put<double>(out, 155 + 8 * a, spec.offset[a]);
  }
  if (spec.minor >= 4 && header_size >= 375) {
    las_put<std::uint64_t>(out, 247,
                           static_cast<std::uint64_t>(spec.count_64 >= 0 ? spec.count_64 : n));
  }
  out += vlrs;
  out.append(spec.padding, '\0');  // records follow here even when point_offset lies
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    std::string record(record_length, static_cast<char>(0xA5 + i));
    for (int a = 0; a < 3; ++a)
      las_put<std::int32_t>(record, 4 * static_cast<std::size_t>(a), xyz[i][a]);
    out += record;
  }
  out.resize(out.size() - std::min(out.size(), spec.drop_tail_bytes));
  return out;
}

}  // namespace g2s::test_support
