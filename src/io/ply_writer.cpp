// PLY writers: write_mesh (indexed binary little-endian PLY with only the used vertices, in
// order of first use; float unless a coordinate would not survive float, then double; or STL via
// StlWriter), mesh_format_for, and PlyPointWriter, which streams float points to a binary PLY.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/le_bytes.hpp"
#include "io/stl_record.hpp"

namespace g2s {
namespace {

bool survives_float(double v) {
  return std::isnan(v) || static_cast<double>(static_cast<float>(v)) == v;
}

void write_ply_mesh(const std::filesystem::path& target, std::span<const double> xyz,
                    std::span<const Triangle> triangles) {
  const std::size_t points = xyz.size() / 3;
  std::vector<Index> remap(points, kNoIndex);
  std::vector<Index> order;  // old index of each written vertex
  for (const Triangle& t : triangles) {
    for (Index v : t) {
      if (remap[v] == kNoIndex) {
        remap[v] = static_cast<Index>(order.size());
        order.push_back(v);
      }
    }
  }
  bool as_float = true;
  for (Index v : order) {
    for (int k = 0; k < 3; ++k) as_float = as_float && survives_float(xyz[3 * v + k]);
  }
  AtomicFile file(target);
  const char* type = as_float ? "float" : "double";
  const std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment written by g2s\nelement vertex {}\n"
      "property {} x\nproperty {} y\nproperty {} z\nelement face {}\n"
      "property list uchar uint vertex_indices\nend_header\n",
      order.size(), type, type, type, triangles.size());
  file.write(header.data(), header.size());
  char record[24];
  for (Index v : order) {
    char* p = record;
    for (int k = 0; k < 3; ++k) {
      const double c = xyz[3 * static_cast<std::size_t>(v) + k];
      p = as_float ? io::put_le(p, static_cast<float>(c)) : io::put_le(p, c);
    }
    file.write(record, static_cast<std::size_t>(p - record));
  }
  for (const Triangle& t : triangles) {
    char* p = io::put_le(record, std::uint8_t{3});
    for (Index v : t) p = io::put_le(p, static_cast<std::uint32_t>(remap[v]));
    file.write(record, static_cast<std::size_t>(p - record));
  }
  file.commit();
}

std::string point_header(std::uint64_t count) {
  return fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment written by g2s\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n",
      count);
}

}  // namespace

MeshFormat mesh_format_for(const std::filesystem::path& path, bool ascii_stl) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".ply") return MeshFormat::ply_binary;
  return ascii_stl ? MeshFormat::stl_ascii : MeshFormat::stl_binary;
}

void write_mesh(const std::filesystem::path& target, std::span<const double> xyz,
                std::span<const Triangle> triangles, MeshFormat format) {
  const std::size_t points = xyz.size() / 3;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    for (Index v : triangles[i]) {
      if (v >= points) {
        throw Error(Exit::failure,
                    fmt::format("{}: triangle {} uses point {} but there are only {} points",
                                target.string(), i, v, points));
      }
    }
  }
  if (format == MeshFormat::ply_binary) {
    write_ply_mesh(target, xyz, triangles);
    return;
  }
  for (const Triangle& t : triangles) {
    for (const Index v : t) {
      for (int k = 0; k < 3; ++k) require_stl_coordinate(target, xyz[3 * std::size_t{v} + k]);
    }
  }
  StlWriter writer(target, format == MeshFormat::stl_ascii);
  for (const Triangle& t : triangles) {
    writer.add(&xyz[3 * static_cast<std::size_t>(t[0])], &xyz[3 * static_cast<std::size_t>(t[1])],
               &xyz[3 * static_cast<std::size_t>(t[2])]);
  }
  writer.finish();
}

PlyPointWriter::PlyPointWriter(const std::filesystem::path& target, std::uint64_t count)
    : file_(target), expected_(count) {
  const std::string header = point_header(count);
  file_.write(header.data(), header.size());
}

void PlyPointWriter::add(float x, float y, float z) {
  ++count_;
  if (count_ > expected_) return;  // reported by finish()
  char record[12];
  char* p = io::put_le(record, x);
  p = io::put_le(p, y);
  io::put_le(p, z);
  file_.write(record, sizeof record);
}

void PlyPointWriter::finish() {
  if (count_ != expected_) {
    throw Error(Exit::failure,
                fmt::format("{}: {} points were added but the PLY header declares {}",
                            file_.target().string(), count_, expected_));
  }
  file_.commit();
}

}  // namespace g2s
