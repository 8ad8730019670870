// read_points: opens the file once, sniffs the content (the "ply" magic line, else text; binary
// bytes in a non-PLY file are an error) and hands it to the PLY or the XYZ reader. The CLI
// decides what an empty cloud means; at this layer zero points is a valid answer.
#include <string_view>

#include "g2s/io.hpp"
#include "io/mapped_file.hpp"
#include "io/ply_format.hpp"
#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s {

PointCloud read_points(const std::filesystem::path& path, ReadReport* report) {
  ReadReport local;
  ReadReport& r = report != nullptr ? *report : local;
  r = ReadReport{};
  const io::MappedFile file(path);
  if (file.size() == 0) {
    io::fail_input(file.name(), "file is empty (expected a PLY or XYZ/PTS point cloud)");
  }
  if (io::has_ply_magic(file)) {
    const io::PlyHeader header = io::parse_ply_header(file);
    r.format = io::ply_format_name(header.encoding);
    r.declared = header.elements.empty() || header.find("vertex") < 0
                     ? 0
                     : header.elements[static_cast<std::size_t>(header.find("vertex"))].count;
    io::PlyBodyResult body = io::read_ply_body(file, header, io::PlyBodyRequest{});
    PointCloud cloud;
    cloud.xyz = std::move(body.xyz);
    r.points = cloud.size();
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
  return io::read_xyz_points(file, r);
}

}  // namespace g2s
