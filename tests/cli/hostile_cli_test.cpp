// Hostile use of the g2s command line (issue 19): an output that is an input, a device or a
// link; a kept store or growth files made for something else; degenerate clouds; options that
// cannot work; paths that break JSON; a signal after the output is complete. Each runs the real
// CLI and checks the exit code, the message and what is left on disk.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "g2s/io.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"
#include "support/utm_terrain.hpp"
#include "tiling/xxhash64.hpp"

namespace {

namespace fs = std::filesystem;
using g2s::test_support::CliRun;
using g2s::test_support::file_bytes;

constexpr int kOk = 0;
constexpr int kUsage = 2;
constexpr int kBadInput = 3;
constexpr int kWriteFailed = 4;
constexpr int kNoSurface = 5;

class HostileCli : public ::testing::Test {
 protected:
  CliRun run(const std::vector<std::string>& args) {
    return g2s::test_support::run_cli(dir_, args);
  }
  fs::path path(const std::string& name) const { return dir_ / name; }
  // A synthetic cloud of `points` points of `shape`, written once per test.
  fs::path cloud(const std::string& name, const std::string& shape, const std::string& points) {
    const CliRun r = run({"synth", shape, "--points", points, "-o", path(name).string()});
    EXPECT_EQ(r.code, kOk) << r.err;
    return path(name);
  }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(path(name), std::ios::binary) << text;
    return path(name);
  }
  static void expect_says(const CliRun& r, int code, const std::vector<std::string>& parts) {
    EXPECT_EQ(r.code, code) << r.err;
    for (const std::string& part : parts) {
      EXPECT_NE(r.err.find(part), std::string::npos) << "stderr: " << r.err << "\nwants: " << part;
    }
  }

  g2s::test_support::TempFolder folder_{"g2s-hostile-cli"};
  const fs::path dir_ = folder_.path();
};

// Item 1: however the output is spelled, it is refused when it is the input, which stays.
TEST_F(HostileCli, OutputThatIsTheInputIsRefused) {
  const fs::path in = cloud("in.ply", "sphere", "2000");
  const std::string before = file_bytes(in);
  fs::create_symlink(in, path("link.ply"));
  fs::create_hard_link(in, path("hard.ply"));
  fs::create_directories(path("sub"));
  const std::string dotted = (dir_ / "sub" / ".." / "in.ply").string();
  for (const std::string& output :
       {in.string(), path("link.ply").string(), path("hard.ply").string(), dotted}) {
    expect_says(run({"mesh", in.string(), "-o", output}), kUsage, {"is the same file as"});
    expect_says(run({"tile", in.string(), output}), kUsage, {"is the same file as"});
    expect_says(run({"synth", "--from", in.string(), "-o", output}), kUsage,
                {"is the same file as"});
  }
  expect_says(run({"mesh", in.string(), "-o", path("m.ply").string(), "--keep-store", dotted}),
              kUsage, {"is the same file as"});
  EXPECT_EQ(file_bytes(in), before);
  // The store and the mesh of one run at one path, neither there yet.
  expect_says(run({"mesh", in.string(), "-o", path("new.ply").string(), "--keep-store",
                   (dir_ / "sub" / ".." / "new.ply").string()}),
              kUsage, {"is the same file as"});
  EXPECT_FALSE(fs::exists(path("new.ply")));
}

// Item 2: a device or FIFO at the output is left alone; a symbolic link is written through.
TEST_F(HostileCli, SpecialFilesAsOutput) {
  const fs::path in = cloud("in.ply", "sphere", "2000");
  fs::create_symlink("/dev/null", path("null.stl"));
  expect_says(run({"mesh", in.string(), "-o", path("null.stl").string()}), kWriteFailed,
              {"null.stl", "not a regular file"});
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_TRUE(fs::is_symlink(path("null.stl")));
  ASSERT_EQ(mkfifo(path("fifo.ply").c_str(), 0644), 0);
  expect_says(run({"mesh", in.string(), "-o", path("fifo.ply").string()}), kWriteFailed,
              {"fifo.ply", "not a regular file"});
  EXPECT_TRUE(fs::is_fifo(path("fifo.ply")));
  write("target.ply", "old");
  fs::create_symlink("target.ply", path("link.ply"));
  expect_says(run({"mesh", in.string(), "-o", path("link.ply").string(), "-q"}), kOk, {});
  EXPECT_TRUE(fs::is_symlink(path("link.ply")));
  EXPECT_GT(g2s::read_mesh(path("target.ply")).triangles.size(), 3000u);
}

// A legal output name of up to 255 bytes is written, whatever the temporaries beside it (the
// store, the output's temporary, the PLY's spill) add to it: they are named after it cut short.
// Names from 234 bytes used to fail (exit 4, "File name too long").
TEST_F(HostileCli, LongestLegalOutputNames) {
  const fs::path in = cloud("in.ply", "sphere", "2000");
  for (const char* extension : {".stl", ".ply"}) {
    const std::string name = std::string(251, 'x') + extension;
    expect_says(run({"mesh", in.string(), "-o", path(name).string(), "-q"}), kOk, {});
    EXPECT_GT(g2s::read_mesh(path(name)).triangles.size(), 3000u);
  }
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 3u);  // the input and the two meshes: no temporary left
}

// Item 3: a kept store is reused only for the cloud and tiling it was made from.
TEST_F(HostileCli, KeptStoreOfAnotherCloudIsNotReused) {
  const fs::path a = cloud("a.ply", "sphere", "3000");
  const fs::path b = cloud("b.ply", "torus", "3000");
  const std::string store = path("k.store").string();
  ASSERT_EQ(run({"mesh", b.string(), "-o", path("b-alone.ply").string(), "-q"}).code, kOk);
  ASSERT_EQ(
      run({"mesh", a.string(), "-o", path("a.ply.out.ply").string(), "-q", "--keep-store", store})
          .code,
      kOk);
  // A's store is newer than B: it must not be taken for B's.
  const CliRun r =
      run({"mesh", b.string(), "-o", path("b.out.ply").string(), "--keep-store", store});
  expect_says(r, kOk, {"tiling again"});
  EXPECT_EQ(file_bytes(path("b.out.ply")), file_bytes(path("b-alone.ply")));
  // Another --tile-points re-tiles too.
  expect_says(run({"mesh", b.string(), "-o", path("b2.ply").string(), "--keep-store", store,
                   "--tile-points", "1000"}),
              kOk, {"--tile-points", "tiling again"});
  // The same input and options reuse it silently.
  const CliRun again = run({"mesh", b.string(), "-o", path("b3.ply").string(), "--keep-store",
                            store, "--tile-points", "1000"});
  EXPECT_EQ(again.code, kOk);
  EXPECT_EQ(again.err.find("tiling again"), std::string::npos) << again.err;
  // A store of an older format version (here: its version field set to 1) is cut again by
  // mesh, refused by grow.
  std::string old = file_bytes(store);
  old[8] = 1;
  write("old.store", old);
  expect_says(run({"grow", path("old.store").string()}), kBadInput,
              {"store version 1, this g2s reads"});
  expect_says(run({"mesh", b.string(), "-o", path("b5.ply").string(), "--keep-store",
                   path("old.store").string()}),
              kOk, {"store version 1", "tiling again"});
  EXPECT_EQ(file_bytes(path("b5.ply")), file_bytes(path("b-alone.ply")));
  // A file that is no store is never overwritten.
  const std::string before = file_bytes(a);
  expect_says(run({"mesh", b.string(), "-o", path("b4.ply").string(), "--keep-store", a.string()}),
              kUsage, {"not a g2s tile store"});
  EXPECT_EQ(file_bytes(a), before);
}

// Item 4: growth files remember their options; grow redoes others, stitch refuses them.
TEST_F(HostileCli, GrowthsMadeWithOtherOptions) {
  const fs::path in = cloud("in.ply", "torus", "4000");
  const std::string store = path("s.store").string();
  ASSERT_EQ(run({"tile", in.string(), store, "-q", "--tile-points", "1500"}).code, kOk);
  ASSERT_EQ(run({"grow", store, "-q"}).code, kOk);
  const CliRun regrow = run({"grow", store, "--max-radius", "2"});
  expect_says(regrow, kOk, {"(0 already there)"});
  expect_says(run({"stitch", store, "-o", path("m.ply").string()}), kUsage,
              {"tile-000000.g2sgrow", "other mesh options"});
  EXPECT_FALSE(fs::exists(path("m.ply")));
  expect_says(run({"stitch", store, "-o", path("m.ply").string(), "--max-radius", "2", "-q"}), kOk,
              {});
  // The message names every option that must match, the hole options too.
  ASSERT_EQ(run({"grow", store, "-q", "--max-hole-edges", "0"}).code, kOk);
  expect_says(run({"stitch", store, "-o", path("h.ply").string()}), kUsage,
              {"other mesh options", "--max-hole-edges", "--max-hole-rings"});
}

// Item 5: points on one line within float precision, also with one stray point, are no
// surface; a cloud with two points off the line is meshed.
TEST_F(HostileCli, CollinearWithinFloatIsNoSurface) {
  std::string line, stray, plane;
  for (int i = 0; i < 2000; ++i)
    line += fmt::format("{} {} {}\n", i * 0.1, 2 * i * 0.1, 3 * i * 0.1);
  stray = line + "5 0 0\n";
  for (const auto& [name, text] : {std::pair{"line.xyz", line}, std::pair{"stray.xyz", stray}}) {
    const CliRun r = run({"mesh", write(name, text).string(), "-o", path("m.ply").string()});
    expect_says(r, kNoSurface, {name, "lie on one straight line"});
    EXPECT_FALSE(fs::exists(path("m.ply")));
  }
  const CliRun far =
      run({"mesh", write("far.xyz", line + "5000 0 0\n").string(), "-o", path("m.ply").string()});
  expect_says(far, kNoSurface, {"but the one at (5000, 0, 0)"});
}

// Item 14: a sphere and one point at 1e30 names the true reason (float precision), not a line.
TEST_F(HostileCli, FarStrayPointIsLeftOutOfTheMesh) {
  // A stray point at 1e30 stretched the one tile's float frame until the rest merged (exit 5).
  // It now gets a tile of its own (kStrayGap), the surface check judges the grid's tile, and
  // the grid is meshed as it is alone.
  std::string text;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j)
      text += fmt::format("{} {} {}\n", i * 0.1, j * 0.1, 0.01 * ((i * j) % 5));
  }
  const CliRun alone =
      run({"mesh", write("grid.xyz", text).string(), "-o", path("alone.ply").string()});
  ASSERT_EQ(alone.code, kOk) << alone.err;
  const CliRun r =
      run({"mesh", write("far.xyz", text + "1e30 0 0\n").string(), "-o", path("m.ply").string()});
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_EQ(r.err.find("stray point"), std::string::npos) << r.err;
  const g2s::IndexedMesh mesh = g2s::read_mesh(path("m.ply"));
  EXPECT_EQ(mesh.triangles.size(), g2s::read_mesh(path("alone.ply")).triangles.size());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) EXPECT_LT(mesh.xyz[3 * v], 4.0);
}

// Strays scattered over a box far wider than the scan, which no single cut separates from it,
// leave tiles too wide for the mesher's float frame: refused (exit 5) with that reason, before
// meshing or where a seam's points merge in float (that seam used to stop on an internal error,
// exit 1, once tiles had frames of their own).
TEST_F(HostileCli, ScatteredStrayPointsTooWideForFloatAreRefused) {
  std::string text = g2s::test_support::utm_terrain_xyz(200);
  std::uint64_t state = 12345;  // a fixed sequence spread over [-1e6, 1e7) on each axis
  const auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return -1e6 + 1.1e7 * static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (int k = 0; k < 50; ++k) text += fmt::format("{} {} {}\n", next(), next(), next());
  const CliRun r =
      run({"mesh", write("scattered.xyz", text).string(), "-o", path("scattered.ply").string()});
  expect_says(r, kNoSurface, {"float coordinates", "stray point"});
}

// A plane square to x far from zero (x = 1e15, one value: a double no float equals) meshes as
// the same plane at x = 0 does, in as little time: the mesher's frame puts it at 0, not up to
// half a float step (3.4e7) away, where float cannot tell its points apart. At 1e100 too, where
// the step itself is beyond float.
TEST_F(HostileCli, PlaneFarFromZeroMeshesAsAtZero) {
  std::vector<std::uint64_t> triangles;
  for (const std::string x : {"0", "1e15", "1e100"}) {
    std::string text;
    for (int i = 0; i < 60; ++i) {
      for (int j = 0; j < 60; ++j) {
        text +=
            fmt::format("{} {} {}\n", x, 0.01 * i + 0.003 * (j % 3), 0.01 * j + 0.002 * (i % 5));
      }
    }
    const CliRun r = run(
        {"mesh", write("plane.xyz", text).string(), "-o", path("plane.ply").string(), "--json"});
    ASSERT_EQ(r.code, kOk) << x << ": " << r.err;
    const g2s::IndexedMesh mesh = g2s::read_mesh(path("plane.ply"));
    triangles.push_back(mesh.triangles.size());
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      EXPECT_EQ(mesh.xyz[3 * v], std::stod(x));  // the output keeps the coordinate exactly
    }
  }
  EXPECT_GT(triangles[0], 6000u);
  EXPECT_EQ(triangles[1], triangles[0]);
  EXPECT_EQ(triangles[2], triangles[0]);
}

// Coordinates beyond float (±3.4e38): STL cannot hold them (exit 2, nothing written; PLY can);
// synth --from cannot measure a cloud that spans more, nor write such coordinates in its float
// PLY (exit 3, nothing written). Both used to write infinities, or crash, with exit 0 or 139.
TEST_F(HostileCli, CoordinatesBeyondFloat) {
  std::string far;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j)
      far += fmt::format("1e39 {} {}\n", 0.1 * i, 0.1 * j + 0.03 * (i % 2));
  }
  const fs::path in = write("far.xyz", far);
  expect_says(run({"mesh", in.string(), "-o", path("m.stl").string()}), kUsage,
              {"m.stl", "cannot hold the coordinate 1e+39", "write .ply"});
  EXPECT_FALSE(fs::exists(path("m.stl")));
  EXPECT_EQ(run({"mesh", in.string(), "-o", path("m.ply").string(), "-q"}).code, kOk);
  expect_says(run({"synth", "--from", in.string(), "-o", path("s.ply").string()}), kBadInput,
              {"far.xyz", "beyond the 32-bit floats"});
  const fs::path wide = write("wide.xyz", "0 0 0\n1e300 0 0\n0 1 0\n0 0 1\n");
  expect_says(run({"synth", "--from", wide.string(), "-o", path("s.ply").string(), "--noise", "1"}),
              kBadInput, {"wide.xyz", "spacing cannot be measured", "span 1e+300"});
  EXPECT_FALSE(fs::exists(path("s.ply")));
  for (const fs::directory_entry& e : fs::directory_iterator(dir_)) {
    EXPECT_NE(e.path().filename().string()[0], '.') << e.path();  // no temporary left
  }
}

// Items 7 and 9: values that cannot work are refused in one short line saying what is valid.
// The peak memory g2s reports is its own, even when the process that started it held far more
// (Linux carries ru_maxrss over exec): here a Python process touches 400 MB and then becomes g2s.
TEST_F(HostileCli, ReportedPeakIsNotTheStartingProcesss) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3";
  const fs::path torus = cloud("torus.ply", "torus", "2000");
  g2s::test_support::CliOptions options;
  // The runner appends "timeout --foreground 0 g2s ARGS": the script execs g2s itself, dropping
  // the timeout, so that g2s inherits the script's memory high-water mark.
  options.prefix = {"/usr/bin/python3", "-c",
                    "import os, sys\n"
                    "held = bytearray(400 << 20)\n"
                    "for i in range(0, len(held), 4096): held[i] = 1\n"
                    "os.execv(sys.argv[4], sys.argv[4:])"};
  const CliRun r = g2s::test_support::run_cli(
      dir_, {"mesh", torus.string(), "-o", path("torus.stl").string(), "--json"}, options);
  ASSERT_EQ(r.code, kOk) << r.err;
  EXPECT_LT(g2s::test_support::json_number(r.out, "peak_rss_mb"), 200.0) << r.out;
}

TEST_F(HostileCli, OptionsThatCannotWork) {
  const std::string in = cloud("in.ply", "sphere", "2000").string();
  const std::string out = path("m.ply").string();
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"mesh", in, "-o", out, "--max-fold", "nan"}, "a number from 10 to 179"},
      {{"mesh", in, "-o", out, "--max-radius", "inf"}, "a number from 1 to 1000"},
      {{"mesh", in, "-o", out, "--radius-steps", "nan"}, "--radius-steps"},
      {{"mesh", in, "-o", out, "--radius-steps", "2", "1"}, "increasing"},
      {{"grow", "x.store", "--radius-steps", "1", "-1"}, "--radius-steps"},
      {{"mesh", in, "-o", out, "--tile-points", "10"}, "from 500"},
      {{"synth", "sphere", "-n", "1000", "--noise", "nan", "-o", out}, "a number from 0 to 100"},
      {{"tile", in, path("s.store").string(), "--tile-points", "1"}, "from 500"},
      {{"mesh", in, "-o", out, "--threads", "-1"}, "a whole number from 0 to"},
      {{"mesh", in, "-o", out, "--memory", "-5G"}, "such as 512M or 4G"},
      {{"synth", "sphere", "-n", "1000", "--seed", "-1", "-o", out}, "a whole number from 0 to"},
      {{"frobnicate"}, "unknown command 'frobnicate'; the commands are mesh"},
  };
  for (const auto& [args, says] : cases) {
    const CliRun r = run(args);
    EXPECT_EQ(r.code, kUsage) << fmt::format("{}", fmt::join(args, " ")) << "\n" << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
    EXPECT_LT(r.err.size(), 200u) << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
}

// Item 8: an output format g2s does not write is refused, not replaced by another.
TEST_F(HostileCli, UnsupportedOutputFormats) {
  const std::string in = cloud("in.ply", "sphere", "2000").string();
  expect_says(run({"mesh", in, "-o", path("m.obj").string()}), kUsage, {"'.obj'", ".stl or .ply"});
  expect_says(run({"mesh", in, "-o", path("mesh").string()}), kUsage, {"no extension"});
  expect_says(run({"mesh", in, "-o", path("m.ply").string(), "--ascii"}), kUsage,
              {"--ascii applies to STL only"});
  ASSERT_EQ(run({"mesh", in, "-o", path("m.stl").string(), "-q"}).code, kOk);
  expect_says(run({"render", path("m.stl").string(), "-o", path("m.jpg").string()}), kUsage,
              {"must end in .png"});
  expect_says(run({"synth", "--from", in, "-o", path("c.xyz").string()}), kUsage,
              {"must end in .ply"});
  for (const char* name : {"m.obj", "mesh", "m.jpg", "c.xyz"}) EXPECT_FALSE(fs::exists(path(name)));
}

// Item 10: endless devices are refused by every command that reads.
TEST_F(HostileCli, EndlessDevicesAreBadInput) {
  const std::string mesh = path("m.stl").string();
  ASSERT_EQ(run({"mesh", cloud("in.ply", "sphere", "2000").string(), "-o", mesh, "-q"}).code, kOk);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"stats", "/dev/zero"},
        {"stats", mesh, "--points", "/dev/zero"},
        {"render", "/dev/zero", "-o", path("x.png").string()},
        {"tile-info", "/dev/zero"},
        {"grow", "/dev/zero"},
        {"synth", "--from", "/dev/zero", "-o", path("x.ply").string()}}) {
    expect_says(run(args), kBadInput, {"/dev/zero", "not a regular file"});
  }
}

// Item 13: a mesh with a vertex at NaN draws its finite triangles, with a warning.
TEST_F(HostileCli, RenderLeavesOutNonFiniteTriangles) {
  const fs::path mesh = write("nan.ply",
                              "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                              "property float y\nproperty float z\nelement face 2\n"
                              "property list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\nnan 0 0\n3 0 1 2\n3 1 3 2\n");
  const CliRun r = run({"render", mesh.string(), "-o", path("p.png").string(), "--size", "64x64"});
  expect_says(r, kOk, {"1 of 2 triangles have a vertex at NaN"});
  const std::string png = file_bytes(path("p.png"));
  ASSERT_FALSE(png.empty());
  // The blank picture (no triangle drawn) of the same size compresses to fewer bytes.
  const fs::path none = write("none.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                              "property float y\nproperty float z\nelement face 0\n"
                              "property list uchar int vertex_indices\nend_header\n0 0 0\n");
  ASSERT_EQ(
      run({"render", none.string(), "-o", path("blank.png").string(), "--size", "64x64"}).code,
      kOk);
  EXPECT_GT(png.size(), file_bytes(path("blank.png")).size());
}

// Item 15: paths with quotes and backslashes give valid JSON strings in every command.
TEST_F(HostileCli, JsonEscapesPaths) {
  fs::create_directories(path("q\"uote\\d"));
  const fs::path in = cloud("q\"uote\\d/in.ply", "sphere", "2000");
  const std::string out = (dir_ / "q\"uote\\d" / "m.ply").string();
  const CliRun mesh = run({"mesh", in.string(), "-o", out, "--json"});
  ASSERT_EQ(mesh.code, kOk) << mesh.err;
  EXPECT_NE(mesh.out.find("q\\\"uote\\\\d/in.ply"), std::string::npos) << mesh.out;
  const std::string store = (dir_ / "q\"uote\\d" / "s.store").string();
  ASSERT_EQ(run({"tile", in.string(), store, "-q"}).code, kOk);
  ASSERT_EQ(run({"grow", store, "-q"}).code, kOk);
  const CliRun stitch = run({"stitch", store, "-o", out, "--json"});
  ASSERT_EQ(stitch.code, kOk) << stitch.err;
  EXPECT_NE(stitch.out.find("q\\\"uote\\\\d/s.store"), std::string::npos) << stitch.out;
  EXPECT_EQ(stitch.out.find("q\"uote"), std::string::npos) << stitch.out;
}

// Item 16: messages name what the user typed, and duplicates alone raise no stray warning.
TEST_F(HostileCli, MessagesNameTheUsersFiles) {
  std::string text;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      const std::string p = fmt::format("{} {} {}\n", i * 0.125, j * 0.125, 0.0);
      text += p + p;  // every point twice
    }
  }
  const CliRun dup = run({"mesh", write("dup.xyz", text).string(), "-o", path("d.ply").string()});
  EXPECT_EQ(dup.code, kOk) << dup.err;
  EXPECT_EQ(dup.err.find("stray point"), std::string::npos) << dup.err;
  const CliRun from =
      run({"synth", "--from", write("one.xyz", "1 2 3\n").string(), "-o", path("o.ply").string()});
  expect_says(from, kBadInput, {"one.xyz: ", "at least two distinct points"});
  // A growth file whose point count disagrees with its tile (header checksum made good): the
  // stitcher's check names the file and the tile.
  const fs::path in = cloud("in.ply", "sphere", "2000");
  const std::string store = path("s.store").string();
  ASSERT_EQ(run({"tile", in.string(), store, "-q"}).code, kOk);
  ASSERT_EQ(run({"grow", store, "-q"}).code, kOk);
  const fs::path growth = fs::path(store + ".grown") / "tile-000000.g2sgrow";
  std::string bytes = file_bytes(growth);
  ASSERT_GT(bytes.size(), 128u);
  std::uint64_t points = 0;
  std::memcpy(&points, bytes.data() + 48, 8);
  points += 1;
  std::memcpy(bytes.data() + 48, &points, 8);
  const std::uint64_t checksum = g2s::tiling::xxhash64(bytes.data(), 120);
  std::memcpy(bytes.data() + 120, &checksum, 8);
  write(growth.lexically_relative(dir_).string(), bytes);
  expect_says(run({"stitch", store, "-o", path("m.ply").string()}), kBadInput,
              {"tile-000000.g2sgrow: tile 0 of ", "point count differs"});
}

// Item 17: --grown naming a file is an output problem (exit 4), not an internal error.
TEST_F(HostileCli, GrownFolderThatCannotBeMade) {
  const fs::path in = cloud("in.ply", "sphere", "2000");
  const std::string store = path("s.store").string();
  ASSERT_EQ(run({"tile", in.string(), store, "-q"}).code, kOk);
  expect_says(run({"grow", store, "--grown", in.string()}), kWriteFailed,
              {in.string(), "cannot make the folder"});
}

// Item 6: a signal once the mesh is complete says so, and the file stays, complete.
TEST_F(HostileCli, SignalDuringTheSummaryKeepsTheCompleteFileAndSaysSo) {
  const fs::path in = cloud("in.ply", "sphere", "300k");
  const fs::path out = path("m.ply");
  g2s::test_support::CliChild child(dir_,
                                    {"mesh", in.string(), "-o", out.string(), "--threads", "1"});
  while (!fs::exists(out)) {
    if (child.ended()) FAIL() << "g2s ended before writing " << out;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  child.send(SIGINT);
  const g2s::test_support::CliRun r = child.wait();
  const std::string& err = r.err;
  if (r.code == 0) GTEST_SKIP() << "the summary ended before the signal arrived";
  EXPECT_EQ(r.code, 130) << err;
  EXPECT_EQ(err.find("no output written"), std::string::npos) << err;
  EXPECT_NE(err.find("is complete"), std::string::npos) << err;
  EXPECT_GT(g2s::read_mesh(out).triangles.size(), 500000u);
}

// The tool starts itself once more with glibc's huge pages for malloc (tools/main.cpp): the
// restarted run must get the same arguments and give the same bytes as a run without them, also
// when the user's GLIBC_TUNABLES names other tunables (which the restart appends to).
TEST_F(HostileCli, HugePagesChangeNoByte) {
  const fs::path in = cloud("t.ply", "torus", "40000");
  const char* had = std::getenv("GLIBC_TUNABLES");
  const std::string before = had != nullptr ? had : "";
  const auto mesh = [&](const char* tunables, const std::string& name) {
    if (tunables != nullptr) {
      setenv("GLIBC_TUNABLES", tunables, 1);
    } else {
      unsetenv("GLIBC_TUNABLES");
    }
    const CliRun r = run({"mesh", in.string(), "-o", path(name).string(), "--json"});
    EXPECT_EQ(r.code, kOk) << r.err;
    EXPECT_NE(r.out.find("\"triangles\":"), std::string::npos) << r.out;
    return file_bytes(path(name));
  };
  const std::string with = mesh(nullptr, "with.stl");
  const std::string without = mesh("glibc.malloc.hugetlb=0", "without.stl");
  const std::string other = mesh("glibc.malloc.tcache_count=0", "other.stl");
  if (had != nullptr) {
    setenv("GLIBC_TUNABLES", before.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
  EXPECT_FALSE(with.empty());
  EXPECT_EQ(with, without);
  EXPECT_EQ(with, other);
}

}  // namespace
