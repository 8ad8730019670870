// StlWriter: streams triangles to binary STL (80-byte header, count patched at finish, 50 bytes
// per facet) or ASCII STL (shortest round-trip floats, so reading back gives the same floats).
// Normals are the normalised cross product of the float corners; zero for degenerate facets.
#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/le_bytes.hpp"
#include "io/stl_record.hpp"

namespace g2s {
namespace {

// The normal from the float corners alone. Not inlined: GCC 12's SLP vectoriser at -O3 would
// otherwise subtract the double coordinates the corners were rounded from, so that a facet
// rewritten later from its stored floats (MeshStreamWriter's flips) would get another normal.
[[gnu::noinline]] void facet_normal(const float corners[9], float normal[3]) {
  double u[3];
  double v[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = static_cast<double>(corners[3 + k]) - static_cast<double>(corners[k]);
    v[k] = static_cast<double>(corners[6 + k]) - static_cast<double>(corners[k]);
  }
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int k = 0; k < 3; ++k) {
    normal[k] = length > 0.0 && std::isfinite(length) ? static_cast<float>(n[k] / length) : 0.0f;
  }
}

void facet(const double a[3], const double b[3], const double c[3], float corners[9],
           float normal[3]) {
  for (int k = 0; k < 3; ++k) {
    corners[k] = static_cast<float>(a[k]);
    corners[3 + k] = static_cast<float>(b[k]);
    corners[6 + k] = static_cast<float>(c[k]);
  }
  facet_normal(corners, normal);
}

}  // namespace

void require_stl_coordinate(const std::filesystem::path& target, double value) {
  if (std::isfinite(static_cast<float>(value))) return;
  throw Error(Exit::usage,
              fmt::format("{}: STL stores 32-bit floats, which cannot hold the coordinate {:.6g} "
                          "(beyond ±3.4e38); write .ply, which keeps doubles",
                          target.string(), value));
}

void stl_normal(const double a[3], const double b[3], const double c[3], float normal[3]) {
  float corners[9];
  facet(a, b, c, corners, normal);
}

void stl_record(const double a[3], const double b[3], const double c[3], char record[50]) {
  float normal[3];
  stl_normal(a, b, c, normal);
  stl_record(a, b, c, normal, record);
}

void stl_record(const double a[3], const double b[3], const double c[3], const float normal[3],
                char record[50]) {
  char* p = record;
  for (int k = 0; k < 3; ++k) p = io::put_le(p, normal[k]);
  for (const double* corner : {a, b, c}) {
    for (int k = 0; k < 3; ++k) p = io::put_le(p, static_cast<float>(corner[k]));
  }
  io::put_le(p, std::uint16_t{0});
}

StlWriter::StlWriter(const std::filesystem::path& target, bool ascii)
    : file_(target), ascii_(ascii) {
  if (ascii_) {
    file_.write("solid g2s\n", 10);
  } else {
    char header[84] = {};
    const char text[] = "binary STL written by g2s";
    std::memcpy(header, text, sizeof text - 1);
    std::memset(header + sizeof text - 1, ' ', 80 - (sizeof text - 1));
    file_.write(header, sizeof header);  // the count (bytes 80..83) is patched by finish()
  }
}

void StlWriter::add(const double a[3], const double b[3], const double c[3]) {
  if (ascii_) {
    float corners[9];
    float normal[3];
    facet(a, b, c, corners, normal);
    fmt::memory_buffer out;
    fmt::format_to(std::back_inserter(out),
                   "facet normal {} {} {}\n  outer loop\n    vertex {} {} {}\n    vertex {} {} {}\n"
                   "    vertex {} {} {}\n  endloop\nendfacet\n",
                   normal[0], normal[1], normal[2], corners[0], corners[1], corners[2], corners[3],
                   corners[4], corners[5], corners[6], corners[7], corners[8]);
    file_.write(out.data(), out.size());
  } else {
    if (count_ >= std::numeric_limits<std::uint32_t>::max()) {
      throw Error(Exit::write_failed,
                  fmt::format("{}: more than {} triangles do not fit in a binary STL",
                              file_.target().string(), std::numeric_limits<std::uint32_t>::max()));
    }
    char record[50];
    stl_record(a, b, c, record);
    file_.write(record, sizeof record);
  }
  ++count_;
}

void StlWriter::finish() {
  if (ascii_) {
    file_.write("endsolid g2s\n", 13);
  } else {
    char count[4];
    io::put_le(count, static_cast<std::uint32_t>(count_));
    file_.write_at(80, count, sizeof count);
  }
  file_.commit();
}

}  // namespace g2s
