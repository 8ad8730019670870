// read_points and scan_points: open the file once, sniff the content (the "ply" magic line, else
// text; binary bytes in a non-PLY file are an error) and hand it to the PLY or the XYZ reader,
// which either collects the points (read_points) or streams them to a sink in bounded memory
// (scan_points, for the tile store). One path, so both number and reject points alike. The CLI
// decides what an empty cloud means; at this layer zero points is a valid answer.
#include <string_view>

#include "g2s/io.hpp"
#include "io/mapped_file.hpp"
#include "io/ply_format.hpp"
#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s {
namespace {

// Reads `path` into the returned cloud (sink == nullptr) or streams it to the sink.
PointCloud read_or_scan(const std::filesystem::path& path, const io::PointSink* sink,
                        ReadReport& r) {
  r = ReadReport{};
  const io::MappedFile file(path, sink == nullptr ? io::MapMode::whole : io::MapMode::stream);
  if (file.size() == 0) {
    io::fail_input(file.name(), "file is empty (expected a PLY or XYZ/PTS point cloud)");
  }
  if (io::has_ply_magic(file)) {
    const io::PlyHeader header = io::parse_ply_header(file);
    r.format = io::ply_format_name(header.encoding);
    r.declared = header.elements.empty() || header.find("vertex") < 0
                     ? 0
                     : header.elements[static_cast<std::size_t>(header.find("vertex"))].count;
    io::PlyBodyRequest request;
    request.points = sink;
    io::PlyBodyResult body = io::read_ply_body(file, header, request);
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
      io::fail_input(file.name(),
                     "byte {}: binary data (byte value 0x{:02x}) in a file that is not PLY (it "
                     "does not start with a 'ply' line); expected a PLY or an XYZ/PTS text point "
                     "cloud",
                     i, c);
    }
  }
  return io::read_xyz_points(file, r, sink);
}

}  // namespace

PointCloud read_points(const std::filesystem::path& path, ReadReport* report) {
  ReadReport local;
  return read_or_scan(path, nullptr, report != nullptr ? *report : local);
}

namespace io {

void scan_points(const std::filesystem::path& path, const PointSink& sink, ReadReport& report) {
  read_or_scan(path, &sink, report);
}

}  // namespace io
}  // namespace g2s
