// Hostile input to the readers (issue 19): files that never end, decimal commas, a PTS count
// that disagrees with its body, a second vertex element, numbers beyond double, a binary STL
// whose header starts with "solid", faces missing after the vertices. Each is a bad_input
// Error naming the file and the place.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
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

}  // namespace
