// read_points and scan_points: open the file once, sniff the content (the "LASF" signature, the
// "ply" magic line, else text; binary bytes in another file are an error) and hand it to the
// LAS, PLY or XYZ reader, which either collects the points (read_points) or streams them to a
// sink in bounded memory (scan_points, for the tile store). One path, so both number and reject
// points alike. The CLI decides what an empty cloud means; at this layer zero points is a valid
// answer.
#include <algorithm>
#include <string_view>

#include "g2s/io.hpp"
#include "io/mapped_file.hpp"
#include "io/ply_format.hpp"
#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s {
namespace io {
namespace {

// Bytes from `end` on that hold something: all of them in a binary body, none when an ASCII
// body is followed only by blanks and line ends.
std::uint64_t bytes_holding_data(const MappedFile& file, std::size_t end, bool ascii) {
  const std::string_view rest = file.view().substr(std::min(end, file.size()));
  if (!ascii) return rest.size();
  for (char c : rest) {
    if (!is_blank(c) && c != '\n') return rest.size();
  }
  return 0;
}

// Reads `file` into the returned cloud (sink == nullptr) or streams it to the sink.
PointCloud read_or_scan(const MappedFile& file, const RunSink* sink, ReadReport& r) {
  r = ReadReport{};
  if (file.size() == 0) {
    fail_input(file.name(), "file is empty (expected a PLY, LAS or XYZ/PTS point cloud)");
  }
  if (has_las_signature(file)) return read_las_points(file, r, sink);
  if (has_ply_magic(file)) {
    const PlyHeader header = parse_ply_header(file);
    const int vertex = header.find("vertex");
    r.format = ply_format_name(header.encoding);
    r.declared = vertex < 0 ? 0 : header.elements[static_cast<std::size_t>(vertex)].count;
    PlyBodyRequest request;
    request.points = sink;
    PlyBodyResult body = read_ply_body(file, header, request);
    // The body was walked to its declared end (a file cut short inside it is an error there).
    r.ignored_bytes = bytes_holding_data(file, body.end, header.encoding == PlyEncoding::ascii);
    PointCloud cloud;
    cloud.xyz = std::move(body.xyz);
    r.points = cloud.size() + body.streamed;
    r.non_finite = body.non_finite;
    return cloud;
  }
  // Text is expected: printable bytes, blanks and line ends (UTF-8 in comments is fine).
  const std::string_view head = file.view().substr(0, 1 << 16);
  for (std::size_t i = 0; i < head.size(); ++i) {
    const auto c = static_cast<unsigned char>(head[i]);
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v') {
      fail_input(file.name(),
                 "byte {}: binary data (byte value 0x{:02x}) in a file that is not PLY or LAS "
                 "(it starts with neither a 'ply' line nor 'LASF'); expected a PLY, a LAS or an "
                 "XYZ/PTS text point cloud",
                 i, c);
    }
  }
  return read_xyz_points(file, r, sink);
}

}  // namespace

PointCloud read_points_from(const MappedFile& file, ReadReport& report) {
  return read_or_scan(file, nullptr, report);
}

void scan_runs(const std::filesystem::path& path, const RunSink& sink, ReadReport& report) {
  const MappedFile file(path, MapMode::stream);
  read_or_scan(file, &sink, report);
}

void scan_points(const std::filesystem::path& path, const PointSink& sink, ReadReport& report) {
  scan_runs(
      path, [&sink](std::vector<double>& xyz) { sink(xyz); }, report);
}

}  // namespace io

PointCloud read_points(const std::filesystem::path& path, ReadReport* report) {
  ReadReport local;
  const io::MappedFile file(path, io::MapMode::whole);
  return io::read_points_from(file, report != nullptr ? *report : local);
}

}  // namespace g2s
