// The bad input matrix of issue 5: one test per kind of file scanners and other tools write, each
// running the real `g2s mesh` on a file written here and checking the exit code (README.md, "Exit
// codes") and the words of the message. Every run has a deadline, so a hang fails its test.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/io.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"
#include "support/unprivileged.hpp"

namespace {

namespace fs = std::filesystem;
using Point = std::array<double, 3>;

constexpr int kOk = 0;
constexpr int kBadInput = 3;
constexpr int kWriteFailed = 4;
constexpr int kNoSurface = 5;

using g2s::test_support::CliRun;
using g2s::test_support::file_bytes;
using g2s::test_support::json_number;

// A 30 x 30 grid of points 0.125 apart, exact in binary, on the surface z = height(x, y).
template <typename Height>
std::vector<Point> grid_points(Height height) {
  std::vector<Point> points;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      const double x = i * 0.125, y = j * 0.125;
      points.push_back({x, y, height(x, y)});
    }
  }
  return points;
}

// A gently curved patch, a typical open scan.
std::vector<Point> wavy_patch() {
  return grid_points([](double x, double y) {
    return static_cast<double>(static_cast<float>(0.3 * std::sin(x) * std::cos(y)));
  });
}

// Little- or big-endian float PLY bytes for `points`, declaring `declared` vertices.
std::string binary_ply(const std::vector<Point>& points, std::size_t declared, bool big_endian) {
  std::string bytes = fmt::format(
      "ply\nformat {} 1.0\nelement vertex {}\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n",
      big_endian ? "binary_big_endian" : "binary_little_endian", declared);
  for (const Point& p : points) {
    for (double c : p) {
      std::uint32_t u = std::bit_cast<std::uint32_t>(static_cast<float>(c));
      if (big_endian == (std::endian::native == std::endian::little)) u = __builtin_bswap32(u);
      bytes.append(reinterpret_cast<const char*>(&u), sizeof u);
    }
  }
  return bytes;
}

// XYZ text with the shortest digits that read back as the same double.
std::string xyz_text(const std::vector<Point>& points) {
  std::string text;
  for (const Point& p : points) text += fmt::format("{} {} {}\n", p[0], p[1], p[2]);
  return text;
}

class BadInput : public g2s::test_support::FolderTest {
 protected:
  // Runs the g2s CLI with `args`; a run past `seconds` is killed and fails the test as a hang.
  CliRun run(const std::vector<std::string>& args, double seconds = 60.0) {
    g2s::test_support::CliOptions options;
    options.seconds = seconds;
    options.as_nobody = unprivileged_;
    return g2s::test_support::run_cli(dir_, args, options);
  }

  // `g2s mesh input -o output` plus extra arguments.
  CliRun mesh(const fs::path& input, const fs::path& output, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"mesh", input.string(), "-o", output.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  }

  // Expects exit code `code`, a stderr holding every part, and nothing at `output` when the run
  // failed.
  void expect_failure(const CliRun& r, int code, std::initializer_list<std::string_view> parts,
                      const fs::path& output) {
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_NE(r.err.find("g2s: error: "), std::string::npos) << r.err;
    for (std::string_view part : parts) {
      EXPECT_NE(r.err.find(part), std::string::npos)
          << "stderr: " << r.err << "\nshould contain: " << part;
    }
    EXPECT_FALSE(fs::exists(output)) << output << " was written";
  }

  fs::path out() const { return dir_ / "mesh.ply"; }

  // Root reads and writes past permissions: a permission test run by root runs the binary as
  // user nobody instead, with the test folder opened to it.
  void run_unprivileged() {
    if (::geteuid() != 0) return;
    unprivileged_ = true;
    g2s::test_support::open_to_others(dir_);
  }
  bool unprivileged_ = false;
};

TEST_F(BadInput, EmptyFileIsBadInput) {
  const fs::path in = write("empty.ply", "");
  expect_failure(mesh(in, out()), kBadInput, {"empty.ply", "file is empty"}, out());
}

TEST_F(BadInput, HeaderOnlyPlyDeclaringPointsIsTruncated) {
  const fs::path in = write("header.ply", binary_ply({}, 900, false));
  expect_failure(mesh(in, out()), kBadInput,
                 {"header.ply", "ends right after the header", "declares 900 vertex"}, out());
}

// A well-formed file without usable points: read fine, but there is nothing to mesh.
TEST_F(BadInput, EmptyCloudIsNoSurface) {
  const fs::path none = write("none.ply", binary_ply({}, 0, false));
  expect_failure(mesh(none, out()), kNoSurface, {"none.ply", "the cloud has no points"}, out());
  const fs::path all_nan = write("nan.xyz", "nan 0 0\n0 inf 0\n");
  expect_failure(mesh(all_nan, out()), kNoSurface,
                 {"nan.xyz", "the cloud has no points", "2 points with NaN or Inf"}, out());
}

TEST_F(BadInput, HeaderDeclaringMorePointsThanTheBodyHoldsIsTruncated) {
  const fs::path in = write("more.ply", binary_ply(wavy_patch(), 910, false));
  expect_failure(mesh(in, out()), kBadInput, {"more.ply", "vertex 901 of 910", "truncated"}, out());
}

// Bytes after the declared vertices cannot be told from trailing garbage: they are ignored with
// a note, and the declared points are meshed.
TEST_F(BadInput, HeaderDeclaringFewerPointsMeshesThemAndNotesTheRest) {
  const fs::path in = write("fewer.ply", binary_ply(wavy_patch(), 890, false));
  const CliRun r = mesh(in, out());
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_NE(r.err.find("120 bytes after the 890 declared vertices ignored"), std::string::npos)
      << r.err;
  const g2s::IndexedMesh written = g2s::read_mesh(out());
  EXPECT_GT(written.triangles.size(), 1500u);
  EXPECT_LE(written.vertex_count(), 890u);
}

TEST_F(BadInput, TruncatedBinaryBodyNamesTheRow) {
  std::string bytes = binary_ply(wavy_patch(), 900, false);
  bytes.resize(bytes.size() - 6);  // the last row loses its z and half of its y
  const fs::path in = write("cut.ply", bytes);
  expect_failure(mesh(in, out()), kBadInput, {"cut.ply", "file ends inside vertex 900 of 900"},
                 out());
}

TEST_F(BadInput, RandomBytesAreNotACloud) {
  std::string bytes(4096, '\0');
  std::uint64_t state = 42;
  for (char& c : bytes) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    c = static_cast<char>(state >> 56);
  }
  const fs::path in = write("noise.bin", bytes);
  expect_failure(mesh(in, out()), kBadInput, {"noise.bin", "binary data", "not PLY"}, out());
}

TEST_F(BadInput, UnknownPropertyTypeNamesTheHeaderLine) {
  const fs::path in = write("type.ply",
                            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                            "property float y\nproperty float128 z\nend_header\n0 0 0\n");
  expect_failure(mesh(in, out()), kBadInput,
                 {"type.ply", "line 6", "unknown property type 'float128'"}, out());
}

TEST_F(BadInput, BigEndianMeshesExactlyLikeLittleEndian) {
  const fs::path le = write("le.ply", binary_ply(wavy_patch(), 900, false));
  const fs::path be = write("be.ply", binary_ply(wavy_patch(), 900, true));
  const fs::path le_mesh = dir_ / "le-mesh.ply";
  const fs::path be_mesh = dir_ / "be-mesh.ply";
  const CliRun from_le = mesh(le, le_mesh);
  ASSERT_EQ(from_le.code, kOk) << from_le.err;
  const CliRun from_be = mesh(be, be_mesh);
  ASSERT_EQ(from_be.code, kOk) << from_be.err;
  const std::string le_bytes = file_bytes(le_mesh);
  EXPECT_GT(g2s::read_mesh(le_mesh).triangles.size(), 1500u);
  EXPECT_TRUE(le_bytes == file_bytes(be_mesh)) << "the two meshes differ";
}

TEST_F(BadInput, VertexElementWithoutZ) {
  const fs::path in = write("xy.ply",
                            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                            "property float y\nend_header\n0 0\n1 0\n0 1\n");
  expect_failure(mesh(in, out()), kBadInput, {"xy.ply", "element vertex has no property 'z'"},
                 out());
}

TEST_F(BadInput, NanAndInfPointsAreDroppedCountedAndTheRestMeshes) {
  std::string text = xyz_text(wavy_patch());
  text += "nan 0 0\n0 inf 0\n0 0 -inf\n";
  const fs::path in = write("nan.xyz", text);
  const CliRun r = mesh(in, out(), {"--json"});
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_NE(r.err.find("3 points with NaN or Inf coordinates dropped"), std::string::npos) << r.err;
  EXPECT_EQ(json_number(r.out, "non_finite"), 3.0) << r.out;
  EXPECT_EQ(json_number(r.out, "points"), 900.0) << r.out;
  EXPECT_GT(json_number(r.out, "triangles"), 1500.0) << r.out;
}

TEST_F(BadInput, AllPointsIdenticalIsNoSurface) {
  std::string text;
  for (int i = 0; i < 100; ++i) text += "1.5 -2 3e2\n";
  const fs::path in = write("same.xyz", text);
  expect_failure(mesh(in, out()), kNoSurface,
                 {"same.xyz", "no surface can be formed", "all 100 points are the same point",
                  "nothing written"},
                 out());
}

TEST_F(BadInput, AllPointsCollinearIsNoSurface) {
  std::vector<Point> line;
  for (int i = 0; i < 100; ++i) line.push_back({0.1 * i, 1.0 - 0.2 * i, 5.0 + 0.3 * i});
  const fs::path in = write("line.xyz", xyz_text(line));
  expect_failure(mesh(in, out()), kNoSurface,
                 {"line.xyz", "no surface can be formed", "100 points", "one straight line"},
                 out());
}

// A flat scan is a valid open surface: a tilted plane (exactly coplanar in binary) meshes whole.
TEST_F(BadInput, AllPointsCoplanarMeshAsAnOpenSurface) {
  const fs::path in = write(
      "plane.xyz", xyz_text(grid_points([](double x, double y) { return 0.5 * x + 0.25 * y; })));
  const CliRun r = mesh(in, out());
  ASSERT_EQ(r.code, kOk) << r.err;
  const CliRun stats = run({"stats", out().string(), "--points", in.string(), "--json"});
  ASSERT_EQ(stats.code, kOk) << stats.err;
  const std::string json = stats.out;
  EXPECT_EQ(json_number(json, "non_manifold_edges"), 0.0) << json;
  EXPECT_EQ(json_number(json, "non_manifold_vertices"), 0.0) << json;
  EXPECT_EQ(json_number(json, "orientation_conflicts"), 0.0) << json;
  EXPECT_EQ(json_number(json, "components"), 1.0) << json;
  EXPECT_GE(json_number(json, "coverage"), 0.99) << json;
}

// A cloud of twins (the patch scanned twice and merged: every point with a copy 1/1000 of the
// spacing off) meshes through one of each pair, says so, and is as clean as the patch alone.
TEST_F(BadInput, CloudOfTwinsMeshesThroughOneOfEachPair) {
  const std::vector<Point> patch = wavy_patch();
  std::vector<Point> twins = patch;
  for (std::size_t i = 0; i < patch.size(); ++i) {
    const double o = (i % 2 == 0 ? 1e-4 : -1e-4);
    twins.push_back({patch[i][0] + o, patch[i][1] - o, patch[i][2] + o});
  }
  const fs::path alone_in = write("patch.xyz", xyz_text(patch));
  const fs::path alone_out = dir_ / "patch.ply";
  ASSERT_EQ(mesh(alone_in, alone_out).code, kOk);
  const fs::path in = write("twins.xyz", xyz_text(twins));
  const CliRun r = mesh(in, out());
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_NE(r.err.find(fmt::format("{} duplicate points and near-copies merged", patch.size())),
            std::string::npos)
      << r.err;
  const g2s::IndexedMesh alone = g2s::read_mesh(alone_out);
  const g2s::IndexedMesh written = g2s::read_mesh(out());
  EXPECT_EQ(written.triangles.size(), alone.triangles.size());
  const std::set<Point> originals(patch.begin(), patch.end());
  for (std::size_t v = 0; v < written.vertex_count(); ++v) {
    ASSERT_TRUE(
        originals.count({written.xyz[3 * v], written.xyz[3 * v + 1], written.xyz[3 * v + 2]}))
        << "vertex " << v << " is a copy";
  }
  const CliRun stats = run({"stats", out().string(), "--points", in.string(), "--json"});
  ASSERT_EQ(stats.code, kOk) << stats.err;
  for (const char* defect : {"non_manifold_edges", "non_manifold_vertices", "orientation_conflicts",
                             "crossing_pairs", "degenerate_triangles", "duplicate_triangles"}) {
    EXPECT_EQ(json_number(stats.out, defect), 0.0) << defect << "\n" << stats.out;
  }
  EXPECT_GE(json_number(stats.out, "coverage"), 0.5) << stats.out;
}

// A wild value (a corrupt float read as 1e300) cannot be meshed in float and is named.
TEST_F(BadInput, CoordinateBeyondFloatRangeIsNoSurface) {
  const fs::path in = write("wild.xyz", xyz_text(wavy_patch()) + "0 1e300 0\n2 0 -1e300\n");
  expect_failure(mesh(in, out()), kNoSurface, {"wild.xyz", "the points span 1e+300 along y"},
                 out());
}

TEST_F(BadInput, TwoPointsIsNoSurface) {
  const fs::path in = write("two.xyz", "0 0 0\n1 2 3\n");
  expect_failure(mesh(in, out()), kNoSurface,
                 {"two.xyz", "no surface can be formed", "only 2 distinct points"}, out());
}

// Georeferenced coordinates (easting ~5e5, northing ~5e6, or ECEF ~1e7 m) with centimetre
// spacing: float cannot hold them (its step at 1e7 is 1 m), so meshing runs in a local frame and
// the PLY written holds the input doubles exactly.
TEST_F(BadInput, GeoreferencedCoordinatesMeshLocallyAndAreWrittenBackExactly) {
  std::vector<Point> points = wavy_patch();
  for (Point& p : points) {
    p = {1.0e7 + 0.08 * p[0] + 0.001, 5.0e6 + 0.08 * p[1] + 0.002, 250.0 + 0.08 * p[2]};
  }
  const fs::path in = write("geo.xyz", xyz_text(points));
  const CliRun r = mesh(in, out());
  ASSERT_EQ(r.code, kOk) << r.err;
  const g2s::IndexedMesh written = g2s::read_mesh(out());
  EXPECT_GT(written.triangles.size(), 1500u);
  const std::set<Point> input(points.begin(), points.end());
  for (std::size_t v = 0; v < written.vertex_count(); ++v) {
    const Point p{written.xyz[3 * v], written.xyz[3 * v + 1], written.xyz[3 * v + 2]};
    ASSERT_TRUE(input.count(p)) << fmt::format(
        "vertex {} ({:.17g}, {:.17g}, {:.17g}) is not an "
        "input point",
        v, p[0], p[1], p[2]);
  }
  const CliRun stats = run({"stats", out().string(), "--points", in.string(), "--json"});
  ASSERT_EQ(stats.code, kOk) << stats.err;
  EXPECT_EQ(json_number(stats.out, "non_manifold_vertices"), 0.0) << stats.out;
  EXPECT_EQ(json_number(stats.out, "degenerate_triangles"), 0.0) << stats.out;
  EXPECT_GE(json_number(stats.out, "coverage"), 0.99) << stats.out;
}

// STL cannot hold such coordinates: writing it works but says what is lost.
TEST_F(BadInput, GeoreferencedCoordinatesToStlWarnAboutFloatRounding) {
  std::vector<Point> points = wavy_patch();
  for (Point& p : points) p = {1.0e7 + 0.08 * p[0], 5.0e6 + 0.08 * p[1], 250.0 + 0.08 * p[2]};
  const fs::path stl = dir_ / "geo.stl";
  const CliRun r = mesh(write("geo.xyz", xyz_text(points)), stl);
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_NE(r.err.find("warning: " + stl.string() + ": STL stores 32-bit floats"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("write .ply to keep them exactly"), std::string::npos) << r.err;
}

// A stray point at the origin of a georeferenced scan gets a tile of its own (kStrayGap): the
// scan is meshed in float frames near its points, as it is alone, with no warning. (It used to
// stretch the one tile's frame to the origin, with a warning that points would merge.)
TEST_F(BadInput, GeoreferencedScanWithAStrayPointAtTheOriginMeshesAsAlone) {
  std::string text;
  for (int i = 0; i < 80; ++i) {
    for (int j = 0; j < 80; ++j)
      text += fmt::format("{} {} {}\n", 1.0e7 + 0.25 * i, 5.0e6 + 0.25 * j, 250 + 0.01 * (i % 3));
  }
  const fs::path alone_mesh = dir_ / "alone.ply";
  const CliRun alone = mesh(write("alone.xyz", text), alone_mesh, {"--json"});
  ASSERT_EQ(alone.code, kOk) << alone.err;
  const CliRun r = mesh(write("stray.xyz", "0 0 0\n" + text), out(), {"--json"});
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_EQ(r.err.find("warning: "), std::string::npos) << r.err;
  EXPECT_EQ(json_number(r.out, "duplicates_merged"), 0.0) << r.out;
  EXPECT_EQ(json_number(r.out, "triangles"), json_number(alone.out, "triangles"));
}

// Exact duplicates are merged: the mesh is the one of the distinct points, byte for byte.
TEST_F(BadInput, DuplicatePointsAreMerged) {
  const std::vector<Point> points = wavy_patch();
  std::vector<Point> doubled = points;
  doubled.insert(doubled.end(), points.begin(), points.begin() + 100);
  const fs::path distinct_mesh = dir_ / "distinct.ply";
  const CliRun distinct = mesh(write("distinct.xyz", xyz_text(points)), distinct_mesh);
  ASSERT_EQ(distinct.code, kOk) << distinct.err;
  const CliRun r = mesh(write("doubled.xyz", xyz_text(doubled)), out(), {"--json"});
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_NE(r.err.find("100 duplicate points merged"), std::string::npos) << r.err;
  EXPECT_EQ(json_number(r.out, "duplicates_merged"), 100.0) << r.out;
  EXPECT_TRUE(file_bytes(out()) == file_bytes(distinct_mesh)) << "duplicates changed the mesh";
}

// A dense patch inside a square sampled 16 times more sparsely: the search, sized by the
// patch's spacing, does not reach across the square, whose points are left out. The mesh
// cannot show that, so a note counts them (exactly the points that are not vertices); a clean
// patch, all of whose points are vertices, gets none.
TEST_F(BadInput, PointsLeftOutOfTheMeshAreNoted) {
  std::vector<Point> points;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      if (i >= 16 && i < 24 && j >= 16 && j < 24) continue;  // the patch's place
      points.push_back({i * 0.25, j * 0.25, 0.1 * std::sin(i * 0.25)});
    }
  }
  for (int i = 0; i < 128; ++i) {
    for (int j = 0; j < 128; ++j) {
      const double x = 4 + i * (2.0 / 128), y = 4 + j * (2.0 / 128);
      points.push_back({x, y, 0.1 * std::sin(x)});
    }
  }
  const CliRun r = mesh(write("patch.xyz", xyz_text(points)), out(), {"--json"});
  ASSERT_EQ(r.code, kOk) << r.err;
  const auto distinct = static_cast<std::uint64_t>(json_number(r.out, "points") -
                                                   json_number(r.out, "duplicates_merged"));
  const std::uint64_t left_out =
      distinct - static_cast<std::uint64_t>(json_number(r.out, "vertices"));
  ASSERT_GT(20 * left_out, distinct) << r.out;  // most of the sparse square's 1,536 points
  EXPECT_NE(r.err.find(fmt::format("{} of the {} distinct points", left_out, distinct)),
            std::string::npos)
      << r.err;

  const CliRun clean = mesh(write("clean.xyz", xyz_text(wavy_patch())), out(), {"--json"});
  ASSERT_EQ(clean.code, kOk) << clean.err;
  EXPECT_EQ(clean.err.find("not vertices of the mesh"), std::string::npos) << clean.err;
}

TEST_F(BadInput, DirectoryAsInput) {
  const fs::path folder = dir_ / "scans.ply";
  fs::create_directory(folder);
  expect_failure(mesh(folder, out()), kBadInput, {"scans.ply", "is a directory"}, out());
}

TEST_F(BadInput, UnreadableFile) {
  const fs::path in = write("locked.xyz", xyz_text(wavy_patch()));
  fs::permissions(in, fs::perms::none);
  run_unprivileged();
  expect_failure(mesh(in, out()), kBadInput, {"locked.xyz", "cannot open", "Permission denied"},
                 out());
}

TEST_F(BadInput, OutputInMissingFolder) {
  const fs::path in = write("patch.xyz", xyz_text(wavy_patch()));
  const fs::path target = dir_ / "missing" / "mesh.stl";
  expect_failure(mesh(in, target), kWriteFailed, {"mesh.stl", "No such file or directory"}, target);
  EXPECT_FALSE(fs::exists(dir_ / "missing"));
}

TEST_F(BadInput, OutputInReadOnlyFolder) {
  const fs::path in = write("patch.xyz", xyz_text(wavy_patch()));
  const fs::path folder = dir_ / "read-only";
  fs::create_directory(folder);
  fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec);
  run_unprivileged();
  const fs::path target = folder / "mesh.stl";
  expect_failure(mesh(in, target), kWriteFailed, {"mesh.stl", "Permission denied"}, target);
  EXPECT_TRUE(fs::is_empty(folder));
}

}  // namespace
