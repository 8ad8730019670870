// Tests of the readers (read_points, read_mesh): every PLY encoding and layout, text XYZ/PTS/CSV
// variants, STL binary/ASCII welding, each broken-file case (error code, file name and wording
// in the message), and the real scans of $G2S_DATA_DIR with the counts from its README.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/mapped_file.hpp"
#include "io/readers.hpp"
#include "support/cli.hpp"
#include "support/expect_error.hpp"
#include "support/temp_folder.hpp"
#include "support/unprivileged.hpp"

namespace {

namespace fs = std::filesystem;
using g2s::Exit;

// A fresh folder per test, removed afterwards.
using IoTempDir = g2s::test_support::FolderTest;

using g2s::test_support::expect_error;

// ---- a PLY body builder for every encoding and type ----

enum class Enc { ascii, le, be };

const char* format_line(Enc e) {
  switch (e) {
    case Enc::ascii:
      return "format ascii 1.0\n";
    case Enc::le:
      return "format binary_little_endian 1.0\n";
    case Enc::be:
      return "format binary_big_endian 1.0\n";
  }
  return "";
}

class PlyBody {
 public:
  explicit PlyBody(Enc enc) : enc_(enc) {}

  void scalar(std::string_view type, double v) {
    if (type == "char" || type == "int8") {
      put<std::int8_t>(v);
    } else if (type == "uchar" || type == "uint8") {
      put<std::uint8_t>(v);
    } else if (type == "short" || type == "int16") {
      put<std::int16_t>(v);
    } else if (type == "ushort" || type == "uint16") {
      put<std::uint16_t>(v);
    } else if (type == "int" || type == "int32") {
      put<std::int32_t>(v);
    } else if (type == "uint" || type == "uint32") {
      put<std::uint32_t>(v);
    } else if (type == "float" || type == "float32") {
      put<float>(v);
    } else if (type == "double" || type == "float64") {
      put<double>(v);
    } else {
      ADD_FAILURE() << "bad type " << type;
    }
  }
  void list(std::string_view count_type, std::string_view item_type,
            const std::vector<double>& items) {
    scalar(count_type, static_cast<double>(items.size()));
    for (double v : items) scalar(item_type, v);
  }
  void end_row() {
    if (enc_ == Enc::ascii) bytes += "\n";
  }
  std::string bytes;

 private:
  template <typename T>
  void put(double v) {
    const T value = static_cast<T>(v);
    if (enc_ == Enc::ascii) {
      if constexpr (sizeof(T) == 1) {
        bytes += fmt::format("{} ", static_cast<int>(value));
      } else {
        bytes += fmt::format("{} ", value);
      }
      return;
    }
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    const bool big = enc_ == Enc::be;
    if (big != (std::endian::native == std::endian::big)) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    }
    bytes.append(raw, sizeof(T));
  }
  Enc enc_;
};

struct Pt {
  double x, y, z;
};

const std::vector<Pt> kPoints = {
    {0.5, -1.25, 1000.125}, {-3.0, 2.75, 0.0}, {1e-3, -4e5, 12345.5}, {7.0, 8.0, -9.5}};

void expect_points(const g2s::PointCloud& cloud, const std::vector<Pt>& want, bool as_float) {
  ASSERT_EQ(cloud.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    const double w[3] = {want[i].x, want[i].y, want[i].z};
    for (int k = 0; k < 3; ++k) {
      const double expected = as_float ? static_cast<double>(static_cast<float>(w[k])) : w[k];
      EXPECT_EQ(cloud.xyz[3 * i + k], expected) << "point " << i << " axis " << k;
    }
  }
}

// A PLY with an extra element (with a list) before vertex, x/y/z in odd positions among other
// properties of many types and a list, and a face element plus trailing bytes after it.
std::string odd_layout_ply(Enc enc, const char* coord) {
  std::string h = "ply\n";
  h += format_line(enc);
  h += "comment odd layout\nobj_info test\n";
  h += "element camera 2\nproperty list uchar float k\nproperty uint16 id\n";
  h += "element vertex " + std::to_string(kPoints.size()) + "\n";
  h += "property uchar red\nproperty list int8 uint tags\n";
  h += fmt::format("property {} z\nproperty short s\nproperty {} x\nproperty int32 i\n", coord,
                   coord);
  h += fmt::format("property {} y\nproperty char c\n", coord);
  h += "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  PlyBody b(enc);
  b.list("uchar", "float", {0.5, 1.5, 2.5});
  b.scalar("uint16", 7);
  b.end_row();
  b.list("uchar", "float", {});
  b.scalar("uint16", 8);
  b.end_row();
  for (std::size_t i = 0; i < kPoints.size(); ++i) {
    b.scalar("uchar", 200);
    std::vector<double> tags(i, 42.0);
    b.list("int8", "uint", tags);
    b.scalar(coord, kPoints[i].z);
    b.scalar("short", -5);
    b.scalar(coord, kPoints[i].x);
    b.scalar("int32", -70000);
    b.scalar(coord, kPoints[i].y);
    b.scalar("char", -1);
    b.end_row();
  }
  b.list("uchar", "int", {0, 1, 2});
  b.end_row();
  return h + b.bytes + (enc == Enc::ascii ? "" : "trailing junk is fine");
}

std::string simple_binary_ply(std::uint64_t declared, std::size_t written) {
  std::string s = fmt::format(
      "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n",
      declared);
  PlyBody b(Enc::le);
  for (std::size_t i = 0; i < written; ++i) {
    b.scalar("float", static_cast<double>(i));
    b.scalar("float", 1.0);
    b.scalar("float", 2.0);
  }
  return s + b.bytes;
}

// ---- PLY variants ----

class IoPlyReader : public IoTempDir {};

TEST_F(IoPlyReader, EveryEncodingAndCoordinateType) {
  const struct {
    Enc enc;
    const char* format;
  } encodings[] = {
      {Enc::ascii, "ply-ascii"}, {Enc::le, "ply-binary-le"}, {Enc::be, "ply-binary-be"}};
  for (const auto& e : encodings) {
    for (const char* coord : {"float", "double", "float32", "float64"}) {
      SCOPED_TRACE(fmt::format("{} {}", e.format, coord));
      const fs::path path = write("odd.ply", odd_layout_ply(e.enc, coord));
      g2s::ReadReport report;
      const g2s::PointCloud cloud = g2s::read_points(path, &report);
      const bool as_float =
          std::string_view(coord).starts_with("float") && std::string_view(coord) != "float64";
      expect_points(cloud, kPoints, as_float && e.enc != Enc::ascii);
      EXPECT_EQ(report.format, e.format);
      EXPECT_EQ(report.declared, kPoints.size());
      EXPECT_EQ(report.points, kPoints.size());
      EXPECT_EQ(report.non_finite, 0u);
    }
  }
}

TEST_F(IoPlyReader, IntegerCoordinatesAndEveryTypeName) {
  for (const char* type : {"char", "uchar", "short", "ushort", "int", "uint", "int8", "uint8",
                           "int16", "uint16", "int32", "uint32"}) {
    for (Enc enc : {Enc::ascii, Enc::le, Enc::be}) {
      SCOPED_TRACE(fmt::format("{} {}", type, static_cast<int>(enc)));
      std::string s = std::string("ply\n") + format_line(enc) +
                      fmt::format(
                          "element vertex 2\nproperty {0} x\nproperty {0} y\nproperty {0} "
                          "z\nend_header\n",
                          type);
      PlyBody b(enc);
      for (double v : {1.0, 2.0, 3.0}) b.scalar(type, v);
      b.end_row();  // ascii rows are one per line
      for (double v : {100.0, 0.0, 127.0}) b.scalar(type, v);
      b.end_row();
      const g2s::PointCloud cloud = g2s::read_points(write("int.ply", s + b.bytes));
      EXPECT_EQ(cloud.xyz, (std::vector<double>{1, 2, 3, 100, 0, 127}));
    }
  }
}

TEST_F(IoPlyReader, HandMadeAsciiFixtureWithCrlf) {
  g2s::ReadReport report;
  const g2s::PointCloud cloud =
      g2s::read_points(fs::path(G2S_FIXTURE_DIR) / "io_odd_layout_ascii.ply", &report);
  EXPECT_EQ(report.format, "ply-ascii");
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1.25, -0.5, 3.5, 0.25, 1000, -1, -0.0, 0, 0}));
  EXPECT_TRUE(std::signbit(cloud.xyz[6]));
}

TEST_F(IoPlyReader, CrlfHeaderWithBinaryBody) {
  std::string s =
      "ply\r\nformat binary_little_endian 1.0\r\ncomment crlf\r\nelement vertex 2\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\nend_header\r\n";
  PlyBody b(Enc::le);
  // The body starts with bytes that look like line ends: they must not be eaten.
  for (double v : {std::bit_cast<float>(0x0a0d0a0dU), 1.0f, 2.0f, 3.0f, 4.0f, 5.0f}) {
    b.scalar("float", v);
  }
  const g2s::PointCloud cloud = g2s::read_points(write("crlf.ply", s + b.bytes));
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.xyz[0], static_cast<double>(std::bit_cast<float>(0x0a0d0a0dU)));
  EXPECT_EQ(cloud.xyz[5], 5.0);
}

TEST_F(IoPlyReader, NonFinitePointsAreDroppedAndCounted) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Enc enc : {Enc::ascii, Enc::le, Enc::be}) {
    std::string s = std::string("ply\n") + format_line(enc) +
                    "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "end_header\n";
    PlyBody b(enc);
    const double values[12] = {1.0, 2.0, 3.0, nan, 0.0, 0.0, 4.0, -inf, 0.0, 5.0, 6.0, 7.0};
    for (int i = 0; i < 12; ++i) {
      b.scalar("float", values[i]);
      if (i % 3 == 2) b.end_row();
    }
    g2s::ReadReport report;
    const g2s::PointCloud cloud = g2s::read_points(write("nan.ply", s + b.bytes), &report);
    EXPECT_EQ(cloud.xyz, (std::vector<double>{1, 2, 3, 5, 6, 7}));
    EXPECT_EQ(report.declared, 4u);
    EXPECT_EQ(report.points, 2u);
    EXPECT_EQ(report.non_finite, 2u);
  }
}

TEST_F(IoPlyReader, ZeroPointsIsAnEmptyCloud) {
  g2s::ReadReport report;
  const g2s::PointCloud cloud =
      g2s::read_points(write("zero.ply", simple_binary_ply(0, 0)), &report);
  EXPECT_EQ(cloud.size(), 0u);
  EXPECT_EQ(report.declared, 0u);
}

TEST_F(IoPlyReader, TrailingBytesAfterTheBodyAreFineAndCounted) {
  const fs::path path = write("trail.ply", simple_binary_ply(3, 3) + std::string(5, '\0'));
  g2s::ReadReport report;
  EXPECT_EQ(g2s::read_points(path, &report).size(), 3u);
  EXPECT_EQ(report.ignored_bytes, 5u);
}

// An ASCII body may end in blank lines; a row more than declared is counted as ignored.
TEST_F(IoPlyReader, AsciiRowsBeyondTheDeclaredCountAreCounted) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n1 0 0\n";
  g2s::ReadReport report;
  EXPECT_EQ(g2s::read_points(write("blank.ply", header + "\n \r\n"), &report).size(), 2u);
  EXPECT_EQ(report.ignored_bytes, 0u);
  EXPECT_EQ(g2s::read_points(write("extra.ply", header + "0 1 0\n"), &report).size(), 2u);
  EXPECT_EQ(report.ignored_bytes, 6u);
}

// Bytes after an element that follows the vertices belong to it, not to the vertices: nothing
// is reported then, as that element is not read.
TEST_F(IoPlyReader, ElementsAfterTheVerticesAreNotIgnoredBytes) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n3 0 0 0\n";
  g2s::ReadReport report;
  EXPECT_EQ(g2s::read_points(write("faces.ply", ply), &report).size(), 1u);
  EXPECT_EQ(report.ignored_bytes, 0u);
}

// The fuzz targets read from memory: the same bytes give the same points and the same errors.
TEST_F(IoPlyReader, InMemoryFileReadsLikeTheFileOnDisk) {
  const std::string bytes = simple_binary_ply(3, 3);
  g2s::ReadReport report;
  const g2s::io::MappedFile in_memory("memory.ply", bytes);
  EXPECT_EQ(g2s::io::read_points_from(in_memory, report).xyz,
            g2s::read_points(write("disk.ply", bytes)).xyz);
  const g2s::io::MappedFile cut("cut.ply", std::string_view(bytes).substr(0, bytes.size() - 1));
  expect_error([&] { g2s::io::read_points_from(cut, report); }, Exit::bad_input,
               {"cut.ply", "truncated"});
}

// ---- PLY errors ----

TEST_F(IoPlyReader, EmptyFile) {
  const fs::path path = write("empty.ply", "");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input, {"empty.ply", "empty"});
}

// "ply" alone, without even a line end, is a PLY header cut short, not text without points.
TEST_F(IoPlyReader, MagicWordAlone) {
  for (const char* text : {"ply", "ply\n"}) {
    const fs::path path = write("magic.ply", text);
    expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
                 {"magic.ply", "file ends inside the PLY header"});
  }
}

TEST_F(IoPlyReader, HeaderOnlyWithPoints) {
  const fs::path path = write("header-only.ply", simple_binary_ply(100, 0));
  expect_error(
      [&] { g2s::read_points(path); }, Exit::bad_input,
      {"header-only.ply", "byte ", "right after the header", "100 vertex elements", "truncated"});
}

TEST_F(IoPlyReader, TruncatedBinaryBody) {
  std::string s = simple_binary_ply(100, 56);
  s += std::string(5, '\0');  // part of vertex 57
  const fs::path path = write("cut.ply", s);
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"cut.ply", fmt::format("byte {}", s.size()), "file ends inside vertex 57 of 100",
                "truncated"});
}

TEST_F(IoPlyReader, TruncatedBinaryBodyWithLists) {
  std::string s =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty list uchar int n\n"
      "property double x\nproperty double y\nproperty double z\nend_header\n";
  PlyBody b(Enc::be);
  b.list("uchar", "int", {1, 2});
  for (double v : {1.0, 2.0, 3.0}) b.scalar("double", v);
  b.list("uchar", "int", {1, 2, 3, 4});  // vertex 2 ends inside its list
  const fs::path path = write("cut-list.ply", s + b.bytes);
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"cut-list.ply", "byte ", "vertex 2 of 3", "truncated"});
}

TEST_F(IoPlyReader, TruncatedElementBeforeVertex) {
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement extra 5\nproperty int a\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  const fs::path path = write("cut-extra.ply", s + std::string(9, '\0'));
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"cut-extra.ply", "extra 3 of 5", "truncated"});
}

TEST_F(IoPlyReader, NegativeListCount) {
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty list char int n\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n";
  PlyBody b(Enc::le);
  b.scalar("char", -3);
  const fs::path path = write("negative.ply", s + b.bytes + std::string(12, '\0'));
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"negative.ply", "negative list count -3", "'n'"});
}

TEST_F(IoPlyReader, TruncatedAsciiBody) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 5 6\n";
  const fs::path path = write("cut-ascii.ply", s);
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"cut-ascii.ply", "line 9", "vertex 3 of 3", "truncated"});
}

TEST_F(IoPlyReader, AsciiRowWithTooFewNumbers) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 5\n7 8 9\n";
  const fs::path path = write("few.ply", s);
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"few.ply", "line 9", "vertex 2 of 3", "expected 3 values, found 2"});
}

TEST_F(IoPlyReader, AsciiRowWithListAndTooFewNumbers) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar int n\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n2 7 7 1 2\n";
  const fs::path path = write("few-list.ply", s);
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"few-list.ply", "line 9", "expected 6 values, found 5"});
}

TEST_F(IoPlyReader, AsciiBadNumber) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 abc 6\n";
  const fs::path path = write("bad-number.ply", s);
  expect_error(
      [&] { g2s::read_points(path); }, Exit::bad_input,
      {"bad-number.ply", "line 9", "vertex 2 of 2", "expected a number for property 'y'", "'abc'"});
}

TEST_F(IoPlyReader, UnknownFormat) {
  const fs::path path = write("format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"format.ply", "line 2", "unknown PLY format 'binary_middle_endian'",
                "binary_little_endian"});
}

TEST_F(IoPlyReader, UnknownPropertyType) {
  const fs::path path = write("type.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float16 x\n"
                              "end_header\n1\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"type.ply", "line 4", "unknown property type 'float16'", "float32"});
}

TEST_F(IoPlyReader, UnknownListType) {
  const fs::path path = write("list-type.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar "
                              "int128 n\nend_header\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"list-type.ply", "line 4", "unknown property type 'int128'"});
}

TEST_F(IoPlyReader, VertexWithoutZ) {
  const fs::path path = write("no-z.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                              "property float y\nproperty float nz\nend_header\n1 2 3\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"no-z.ply", "line 3", "no property 'z'", "x, y and z"});
}

TEST_F(IoPlyReader, NoVertexElement) {
  const fs::path path = write("no-vertex.ply",
                              "ply\nformat ascii 1.0\nelement point 1\nproperty float x\n"
                              "end_header\n1\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"no-vertex.ply", "no 'element vertex'"});
}

TEST_F(IoPlyReader, NoEndHeader) {
  const fs::path path =
      write("no-end.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"no-end.ply", "end_header", "truncated"});
}

TEST_F(IoPlyReader, BadElementLineAndUnknownKeyword) {
  const fs::path a = write("element.ply", "ply\nformat ascii 1.0\nelement vertex -4\nend_header\n");
  expect_error([&] { g2s::read_points(a); }, Exit::bad_input,
               {"element.ply", "line 3", "element NAME COUNT"});
  const fs::path b = write("keyword.ply", "ply\nformat ascii 1.0\nelemnt vertex 4\nend_header\n");
  expect_error([&] { g2s::read_points(b); }, Exit::bad_input,
               {"keyword.ply", "line 3", "unknown header keyword 'elemnt'"});
  const fs::path c = write("no-format.ply", "ply\nelement vertex 0\nend_header\n");
  expect_error([&] { g2s::read_points(c); }, Exit::bad_input, {"no-format.ply", "'format'"});
}

// ---- opening problems (any format) ----

class IoReadOpen : public IoTempDir {};

TEST_F(IoReadOpen, MissingFile) {
  const fs::path path = dir_ / "missing.ply";
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"missing.ply", std::strerror(ENOENT)});
  expect_error([&] { g2s::read_mesh(path); }, Exit::bad_input,
               {"missing.ply", std::strerror(ENOENT)});
}

TEST_F(IoReadOpen, DirectoryGiven) {
  expect_error([&] { g2s::read_points(dir_); }, Exit::bad_input,
               {dir_.filename().string(), "is a directory"});
  expect_error([&] { g2s::read_mesh(dir_); }, Exit::bad_input, {"is a directory"});
}

TEST_F(IoReadOpen, UnreadableFile) {
  const fs::path path = write("secret.ply", simple_binary_ply(1, 1));
  fs::permissions(path, fs::perms::none);
  g2s::test_support::open_to_others(dir_);
  EXPECT_EQ(g2s::test_support::as_unprivileged([&] {
              return g2s::test_support::error_mismatch([&] { g2s::read_points(path); },
                                                       Exit::bad_input,
                                                       {"secret.ply", std::strerror(EACCES)});
            }),
            "");
}

TEST_F(IoReadOpen, BinaryFileThatIsNotPly) {
  std::string junk = "PK";
  junk += std::string("\x03\x04\x00\x00\x01", 5);
  const fs::path path = write("archive.zip", junk);
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"archive.zip", "byte 2", "binary data", "PLY"});
}

// ---- text XYZ / PTS / CSV ----

class IoXyzReader : public IoTempDir {};

TEST_F(IoXyzReader, SeparatorsCommentsAndExtraColumns) {
  const std::string text =
      "# comment\n"
      "// another comment\n"
      "\n"
      "1 2 3\n"
      "  4\t5\t6\t0.5 extra text\n"
      "7,8,9\n"
      "10, 11 ,12,255,0,0\n"
      "   \t\n"
      "-1.5e2 +2.25 -0\r\n"
      "1e-3\t\t2e3   3.5";  // no final line end
  g2s::ReadReport report;
  const g2s::PointCloud cloud = g2s::read_points(write("mixed.xyz", text), &report);
  EXPECT_EQ(report.format, "xyz");
  EXPECT_EQ(report.declared, 0u);
  EXPECT_EQ(report.points, 6u);
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, -150, 2.25, -0.0,
                                            1e-3, 2e3, 3.5}));
}

// Classic Mac OS line ends (CR alone): every line is a point, not the first line alone with
// the rest taken as extra columns.
TEST_F(IoXyzReader, CarriageReturnLineEnds) {
  g2s::ReadReport report;
  const g2s::PointCloud cloud =
      g2s::read_points(write("mac.pts", "3\r# comment\r1 2 3\r4 5 6\r7 8 9\r"), &report);
  EXPECT_EQ(report.declared, 3u);
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

TEST_F(IoXyzReader, PtsFixtureWithCountLine) {
  g2s::ReadReport report;
  const g2s::PointCloud cloud =
      g2s::read_points(fs::path(G2S_FIXTURE_DIR) / "io_points.pts", &report);
  EXPECT_EQ(cloud.xyz,
            (std::vector<double>{1.5, 2.5, 3.5, -1, -2, -3, 1e3, 2e-3, 3, 0.125, 0.25, 0.5}));
}

TEST_F(IoXyzReader, CsvFixtureWithColumnNames) {
  const g2s::PointCloud cloud = g2s::read_points(fs::path(G2S_FIXTURE_DIR) / "io_points.csv");
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1.5, 2.5, 3.5, -1, -2, -3, 4, 5, 6}));
}

TEST_F(IoXyzReader, NonFiniteDroppedAndCounted) {
  g2s::ReadReport report;
  const g2s::PointCloud cloud =
      g2s::read_points(write("nan.xyz", "1 2 3\nnan 0 0\n0 inf 0\n4 5 6\n0 0 -inf\n"), &report);
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(report.points, 2u);
  EXPECT_EQ(report.non_finite, 3u);
}

TEST_F(IoXyzReader, OnlyCommentsIsEmpty) {
  EXPECT_EQ(g2s::read_points(write("c.xyz", "# nothing\n\n// here\n")).size(), 0u);
}

TEST_F(IoXyzReader, TooFewNumbers) {
  const fs::path path = write("few.xyz", "# header\n1 2 3\n4 5\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"few.xyz", "line 3", "expected at least 3 numbers (x y z), found 2"});
}

TEST_F(IoXyzReader, BadNumberAndEmptyColumn) {
  const fs::path a = write("bad.xyz", "1 2 3\n4 5 six\n");
  expect_error([&] { g2s::read_points(a); }, Exit::bad_input,
               {"bad.xyz", "line 2", "column 3", "expected a number", "'six'"});
  const fs::path b = write("gap.csv", "1,2,3\n4,,6\n");
  expect_error([&] { g2s::read_points(b); }, Exit::bad_input,
               {"gap.csv", "line 2", "column 2 is empty"});
}

TEST_F(IoXyzReader, CountLineOnlyAtTheStart) {
  const fs::path path = write("count.pts", "2\n1 2 3\n7\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"count.pts", "line 3", "found 1"});
}

TEST_F(IoXyzReader, LargeFileParsedInChunksKeepsOrderAndLineNumbers) {
  // Over 4 MiB, so the parallel chunked path runs.
  std::string text = "# big\n";
  const int n = 300000;
  for (int i = 0; i < n; ++i) text += fmt::format("{} {}.5 -{}\n", i, i, i);
  g2s::ReadReport report;
  const g2s::PointCloud cloud = g2s::read_points(write("big.xyz", text), &report);
  ASSERT_EQ(cloud.size(), static_cast<std::size_t>(n));
  for (int i = 0; i < n; i += 997) {
    EXPECT_EQ(cloud.xyz[3 * i], i);
    EXPECT_EQ(cloud.xyz[3 * i + 1], i + 0.5);
    EXPECT_EQ(cloud.xyz[3 * i + 2], -i);
  }
  // A bad line deep in a later chunk is reported with its true line number.
  text += "1 2\n";
  for (int i = 0; i < 1000; ++i) text += "1 2 3\n";
  const fs::path path = write("big-bad.xyz", text);
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"big-bad.xyz", fmt::format("line {}:", n + 2)});
}

// ---- read_mesh ----

class IoMeshReader : public IoTempDir {};

std::string binary_stl(const std::vector<std::array<float, 9>>& facets, std::string_view header) {
  std::string s(header);
  s.resize(80, ' ');
  const auto n = static_cast<std::uint32_t>(facets.size());
  s.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& f : facets) {
    const float normal[3] = {0, 0, 0};
    s.append(reinterpret_cast<const char*>(normal), 12);
    s.append(reinterpret_cast<const char*>(f.data()), 36);
    s.append(2, '\0');
  }
  return s;
}

TEST_F(IoMeshReader, AsciiStlFixtureIsWelded) {
  // Named .txt because .gitignore ignores *.stl; the format is sniffed from the content anyway.
  const g2s::IndexedMesh mesh =
      g2s::read_mesh(fs::path(G2S_FIXTURE_DIR) / "io_tetra_ascii_stl.txt");
  EXPECT_EQ(mesh.vertex_count(), 4u);
  ASSERT_EQ(mesh.triangles.size(), 4u);
  EXPECT_EQ(mesh.xyz, (std::vector<double>{0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1}));
  EXPECT_EQ(mesh.triangles[0], (g2s::Triangle{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[3], (g2s::Triangle{2, 1, 3}));
}

// Keywords in capitals (some CAD writers) or mixed case read as in lower case.
TEST_F(IoMeshReader, AsciiStlKeywordsInAnyCase) {
  const std::string lower =
      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nendsolid t\n";
  std::string upper = lower, mixed = lower;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  mixed.replace(mixed.find("facet"), 5, "Facet");
  const g2s::IndexedMesh expected = g2s::read_mesh(write("lower.txt", lower));
  ASSERT_EQ(expected.triangles.size(), 1u);
  for (const auto& [name, text] : {std::pair{"upper.txt", upper}, std::pair{"mixed.txt", mixed}}) {
    const g2s::IndexedMesh mesh = g2s::read_mesh(write(name, text));
    EXPECT_EQ(mesh.xyz, expected.xyz) << name;
    EXPECT_EQ(mesh.triangles, expected.triangles) << name;
  }
}

TEST_F(IoMeshReader, BinaryStlWithSolidHeaderIsBinary) {
  // A "solid" header must not make a binary STL look like ASCII; -0 welds with +0.
  const std::string s = binary_stl(
      {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {-0.0f, 0, 0, 0, 1, 0, 1, 0, 0.5f}}, "solid but binary");
  const g2s::IndexedMesh mesh = g2s::read_mesh(write("solid.stl", s));
  EXPECT_EQ(mesh.vertex_count(), 4u);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0], (g2s::Triangle{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[1], (g2s::Triangle{0, 2, 3}));
  EXPECT_EQ(mesh.xyz[9], 1.0);
  EXPECT_EQ(mesh.xyz[11], 0.5);
}

TEST_F(IoMeshReader, PlyMeshWithPolygonsIsFanned) {
  for (Enc enc : {Enc::ascii, Enc::le, Enc::be}) {
    for (const char* list_name : {"vertex_indices", "vertex_index"}) {
      std::string s = std::string("ply\n") + format_line(enc) +
                      "element vertex 5\nproperty double x\nproperty double y\nproperty double "
                      "z\nelement edge 1\nproperty int a\nproperty int b\nelement face 3\n"
                      "property uchar flags\n" +
                      fmt::format("property list ushort uint {}\n", list_name) +
                      "property list uchar float uv\nend_header\n";
      PlyBody b(enc);
      for (int i = 0; i < 5; ++i) {
        b.scalar("double", i + 0.1);
        b.scalar("double", -i);
        b.scalar("double", 0.3);
        b.end_row();
      }
      b.scalar("int", 0);
      b.scalar("int", 1);
      b.end_row();
      b.scalar("uchar", 1);
      b.list("ushort", "uint", {0, 1, 2, 3});  // a quad: two triangles
      b.list("uchar", "float", {0.5, 0.5});
      b.end_row();
      b.scalar("uchar", 1);
      b.list("ushort", "uint", {4, 3});  // an edge: no triangle
      b.list("uchar", "float", {});
      b.end_row();
      b.scalar("uchar", 1);
      b.list("ushort", "uint", {2, 3, 4});
      b.list("uchar", "float", {});
      b.end_row();
      const g2s::IndexedMesh mesh = g2s::read_mesh(write("mesh.ply", s + b.bytes));
      ASSERT_EQ(mesh.vertex_count(), 5u);
      EXPECT_EQ(mesh.xyz[3], 1.1);
      ASSERT_EQ(mesh.triangles.size(), 3u);
      EXPECT_EQ(mesh.triangles[0], (g2s::Triangle{0, 1, 2}));
      EXPECT_EQ(mesh.triangles[1], (g2s::Triangle{0, 2, 3}));
      EXPECT_EQ(mesh.triangles[2], (g2s::Triangle{2, 3, 4}));
    }
  }
}

TEST_F(IoMeshReader, PlyIndexOutOfRange) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
  const fs::path path = write("range.ply", s);
  expect_error([&] { g2s::read_mesh(path); }, Exit::bad_input,
               {"range.ply", "line 13", "face 1 of 1", "vertex index 3 out of range"});
}

TEST_F(IoMeshReader, PlyWithoutFaces) {
  const fs::path path = write("points.ply", simple_binary_ply(2, 2));
  expect_error([&] { g2s::read_mesh(path); }, Exit::bad_input, {"points.ply", "no 'element face'"});
}

TEST_F(IoMeshReader, NotAMesh) {
  const fs::path a = write("junk.stl", std::string(200, 'x'));
  expect_error([&] { g2s::read_mesh(a); }, Exit::bad_input,
               {"junk.stl", "not a mesh file", "binary STL"});
  const fs::path b = write("empty.stl", "");
  expect_error([&] { g2s::read_mesh(b); }, Exit::bad_input, {"empty.stl", "empty"});
}

TEST_F(IoMeshReader, TruncatedBinaryStl) {
  std::string s = binary_stl({{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 0, 0, 0, 1, 0, 1, 0, 0}}, "bin");
  s.resize(s.size() - 7);
  const fs::path path = write("cut.stl", s);
  expect_error([&] { g2s::read_mesh(path); }, Exit::bad_input,
               {"cut.stl", "triangle count 2", "184 bytes", "truncated"});
}

TEST_F(IoMeshReader, BrokenAsciiStl) {
  const std::string facet =
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
      "endfacet\n";
  const fs::path a =
      write("cut-ascii.stl", "solid x\n" + facet + "facet normal 0 0 1\nouter loop\n");
  expect_error([&] { g2s::read_mesh(a); }, Exit::bad_input,
               {"cut-ascii.stl", "facet 2", "truncated"});
  const fs::path b =
      write("bad-vertex.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 zero 0\n");
  expect_error([&] { g2s::read_mesh(b); }, Exit::bad_input,
               {"bad-vertex.stl", "line 4", "expected a number", "'zero'"});
  const fs::path c = write("no-end.stl", "solid x\n" + facet);
  expect_error([&] { g2s::read_mesh(c); }, Exit::bad_input, {"no-end.stl", "endsolid"});
}

// ---- the real scans ----

TEST(IoRealData, ReadmePointCounts) {
  const fs::path dir = g2s::test_support::data_dir();
  G2S_SKIP_WITHOUT_DATA(dir);
  const struct {
    const char* file;
    std::uint64_t points;
  } files[] = {{"closed-kitten.ply", 5210},
               {"closed-bunny-zipper.ply", 35947},
               {"raw-bunny.ply", 362272},
               {"open-bunny-scan-bun000.ply", 40256},
               {"open-table-mug-stereo.ply", 209280},
               {"open-lion-photogrammetry.ply", 341989},
               {"open-autzen-lidar.ply", 110000},
               {"open-alpe-selle-photogrammetry.ply", 6022747}};
  for (const auto& f : files) {
    const fs::path path = dir / f.file;
    if (!fs::exists(path)) {
      ADD_FAILURE() << "missing " << path;
      continue;
    }
    g2s::ReadReport report;
    const g2s::PointCloud cloud = g2s::read_points(path, &report);
    EXPECT_EQ(cloud.size(), f.points) << f.file;
    EXPECT_EQ(report.declared, f.points) << f.file;
    EXPECT_EQ(report.non_finite, 0u) << f.file;
    EXPECT_EQ(report.format, "ply-binary-le") << f.file;
  }
}

}  // namespace
