// Hostile input to the readers (issue 19): files that never end, decimal commas, a PTS count
// that disagrees with its body, a second vertex element, numbers beyond double, a binary STL
// whose header starts with "solid", faces missing after the vertices. Each is a bad_input
// Error naming the file and the place.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <string_view>
#include <tuple>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/readers.hpp"
#include "support/expect_error.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;
using g2s::Exit;
using g2s::test_support::expect_error;

using HostileReaders = g2s::test_support::FolderTest;

// /dev/zero never ends: reading it whole would fill the memory. Every reader refuses it.
TEST_F(HostileReaders, DevicesAreRefusedByEveryReader) {
  expect_error([] { g2s::read_points("/dev/zero"); }, Exit::bad_input,
               {"/dev/zero", "not a regular file"});
  expect_error([] { g2s::read_mesh("/dev/zero"); }, Exit::bad_input,
               {"/dev/zero", "not a regular file"});
}

TEST_F(HostileReaders, DecimalCommasAreRefused) {
  const fs::path path = write("comma.xyz", "100,468 198,797 349,983\n1,5 2,5 3,5\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"comma.xyz", "line 1", "decimal commas"});
  // Commas as separators stay fine, with or without blanks.
  EXPECT_EQ(g2s::read_points(write("csv.xyz", "1,2,3\n4,5,6\n")).size(), 2u);
  EXPECT_EQ(g2s::read_points(write("csv2.xyz", "1, 2, 3\n4, 5, 6\n")).size(), 2u);
}

TEST_F(HostileReaders, PtsCountMustMatchTheBody) {
  const fs::path fewer = write("fewer.pts", "5\n0 0 0\n1 0 0\n0 1 0\n");
  expect_error([&] { g2s::read_points(fewer); }, Exit::bad_input,
               {"fewer.pts", "says 5 points, the file holds 3"});
  g2s::ReadReport report;
  EXPECT_EQ(g2s::read_points(write("right.pts", "3\n0 0 0\n1 0 0\n0 1 0\n"), &report).size(), 3u);
  EXPECT_EQ(report.declared, 3u);
}

TEST_F(HostileReaders, SecondVertexElementIsRefused) {
  const fs::path path = write("two.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                              "property float y\nproperty float z\nelement vertex 1\n"
                              "property float x\nend_header\n0 0 0\n1\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"two.ply", "line 7", "a second element 'vertex'", "line 3"});
}

TEST_F(HostileReaders, SecondPropertyOfOneNameIsRefused) {
  const fs::path path = write("twice.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                              "property float y\nproperty float x\nproperty float z\n"
                              "end_header\n0 0 1 0\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"twice.ply", "line 6", "a second property 'x' in element 'vertex'", "line 4"});
}

TEST_F(HostileReaders, NumbersBeyondDoubleAreNamed) {
  expect_error([&] { g2s::read_points(write("big.xyz", "0 0 0\n1e400 0 0\n")); }, Exit::bad_input,
               {"big.xyz", "line 2", "'1e400'", "beyond the range of double"});
  expect_error(
      [&] {
        g2s::read_points(write("big.ply",
                               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                               "property float y\nproperty float z\nend_header\n0 -1e999 0\n"));
      },
      Exit::bad_input, {"big.ply", "'-1e999'", "beyond the range of double"});
}

// Many exporters start a binary STL's 80-byte header with "solid": a truncated one must get the
// binary STL's message, not an ASCII parse error.
TEST_F(HostileReaders, TruncatedBinaryStlStartingWithSolid) {
  std::string bytes = "solid exported by some tool";
  bytes.resize(80, ' ');
  const std::uint32_t count = 4;
  bytes.append(reinterpret_cast<const char*>(&count), 4);
  bytes.append(50 * 3, '\0');  // one triangle short
  expect_error([&] { g2s::read_mesh(write("solid.stl", bytes)); }, Exit::bad_input,
               {"solid.stl", "binary STL", "triangle count 4", "truncated"});
}

TEST_F(HostileReaders, FacesMissingAfterTheVerticesAreTruncation) {
  const fs::path path = write("nofaces.ply",
                              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                              "property float y\nproperty float z\nelement face 2\n"
                              "property list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n");
  expect_error([&] { g2s::read_points(path); }, Exit::bad_input,
               {"nofaces.ply", "ends after the vertices", "declares 2 face"});
}

// A file cut inside its faces (or any element after the vertices) is truncated too, whatever
// comes before the cut: the elements after the vertices are walked to their declared end, in
// binary (fixed or list rows) and in ASCII, by the point readers (read and streamed) and the mesh
// reader. They used to be read as complete (exit 0).
TEST_F(HostileReaders, FileCutInsideTheFacesIsTruncation) {
  const std::string vertices =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 2\nproperty list uchar int vertex_indices\n";
  std::string body;
  for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) {
    body.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  std::string face;
  face.push_back('\3');
  for (const std::int32_t i : {0, 1, 2}) face.append(reinterpret_cast<const char*>(&i), sizeof i);
  const std::string binary = "ply\nformat binary_little_endian 1.0\n" + vertices + faces +
                             "end_header\n" + body + face + face.substr(0, 6);
  const std::string fixed = "ply\nformat binary_little_endian 1.0\n" + vertices +
                            "element extra 4\nproperty int a\nend_header\n" + body +
                            std::string(10, '\0');
  const std::string ascii =
      "ply\nformat ascii 1.0\n" + vertices + faces + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n";
  for (const auto& [name, text, where] : {std::tuple{"cut-list.ply", binary, "face 2 of 2"},
                                          std::tuple{"cut-fixed.ply", fixed, "extra 3 of 4"},
                                          std::tuple{"cut-ascii.ply", ascii, "face 2 of 2"}}) {
    SCOPED_TRACE(name);
    const fs::path path = write(name, text);
    expect_error([&] { g2s::read_points(path); }, Exit::bad_input, {name, where, "truncated"});
    expect_error(
        [&] {
          g2s::ReadReport report;
          g2s::io::scan_points(
              path, [](std::span<const double>) {}, report);
        },
        Exit::bad_input, {name, where, "truncated"});
  }
  expect_error([&] { g2s::read_mesh(write("cut-mesh.ply", binary)); }, Exit::bad_input,
               {"cut-mesh.ply", "face 2 of 2", "truncated"});
  // Whole, the same files read, and bytes after the body are counted as ignored.
  const fs::path whole = write("whole.ply", binary.substr(0, binary.size() - 6) + face + "tail");
  g2s::ReadReport report;
  EXPECT_EQ(g2s::read_points(whole, &report).size(), 3u);
  EXPECT_EQ(report.ignored_bytes, 4u);
}

}  // namespace
