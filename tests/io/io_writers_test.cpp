// Tests of the writers: STL (binary and ASCII) and PLY meshes round-tripped through read_mesh,
// PlyPointWriter through read_points, mesh_format_for, and AtomicFile's all-or-nothing
// behaviour: missing folder, a path under a regular file, read-only folder, disk full.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "support/expect_error.hpp"
#include "support/temp_folder.hpp"
#include "support/unprivileged.hpp"

namespace {

namespace fs = std::filesystem;
using g2s::Exit;

class IoWriteDir : public ::testing::Test {
 protected:
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_))
      names.push_back(e.path().filename().string());
    return names;
  }
  g2s::test_support::TempFolder folder_{"g2s-io-write"};
  const fs::path dir_ = folder_.path();
};

using g2s::test_support::expect_error;

using g2s::test_support::file_bytes;

// An octahedron (float-exact coordinates) with an unused point in front and one at the end,
// plus a degenerate triangle.
struct TestMesh {
  std::vector<double> xyz;
  std::vector<g2s::Triangle> triangles;
};

TestMesh octahedron(double shift = 0.0) {
  TestMesh m;
  m.xyz = {9, 9, 9,                                                                   // unused
           1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1.5, 0, 0, -1.5, -7, -7, -7};  // unused
  for (double& v : m.xyz) v += shift;
  m.triangles = {{1, 3, 5}, {3, 2, 5}, {2, 4, 5}, {4, 1, 5}, {3, 1, 6},
                 {2, 3, 6}, {4, 2, 6}, {1, 4, 6}, {1, 1, 3}};
  return m;
}

using Corners = std::array<double, 9>;

std::vector<Corners> corners_of(const std::vector<double>& xyz,
                                const std::vector<g2s::Triangle>& triangles, bool as_float) {
  std::vector<Corners> out;
  for (const auto& t : triangles) {
    Corners c{};
    for (int k = 0; k < 3; ++k) {
      for (int a = 0; a < 3; ++a) {
        const double v = xyz[3 * static_cast<std::size_t>(t[k]) + a];
        c[3 * k + a] = as_float ? static_cast<double>(static_cast<float>(v)) : v;
      }
    }
    out.push_back(c);
  }
  return out;
}

// ---- STL ----

class IoStlWriter : public IoWriteDir {};

TEST_F(IoStlWriter, BinaryRoundTrip) {
  const TestMesh m = octahedron(0.1);  // 0.1 shifts make the coordinates non-float-exact
  const fs::path path = dir_ / "mesh.stl";
  g2s::write_mesh(path, m.xyz, m.triangles, g2s::MeshFormat::stl_binary);
  const std::string bytes = file_bytes(path);
  ASSERT_EQ(bytes.size(), 84 + 50 * m.triangles.size());
  EXPECT_NE(bytes.substr(0, 5), "solid");
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  EXPECT_EQ(count, m.triangles.size());
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    float n[3];
    std::memcpy(n, bytes.data() + 84 + 50 * i, sizeof n);
    const double length =
        std::sqrt(double{n[0]} * n[0] + double{n[1]} * n[1] + double{n[2]} * n[2]);
    if (i + 1 == m.triangles.size()) {
      EXPECT_EQ(length, 0.0) << "degenerate facet";
    } else {
      EXPECT_NEAR(length, 1.0, 1e-6) << "facet " << i;
    }
  }
  // Facet 0 is (1,0,0) (0,1,0) (0,0,1.5) shifted: its normal points into +x+y+z.
  float n0[3];
  std::memcpy(n0, bytes.data() + 84, sizeof n0);
  EXPECT_GT(n0[0], 0.0f);
  EXPECT_GT(n0[1], 0.0f);
  EXPECT_GT(n0[2], 0.0f);

  const g2s::IndexedMesh back = g2s::read_mesh(path);
  EXPECT_EQ(back.vertex_count(), 6u);
  EXPECT_EQ(corners_of(back.xyz, back.triangles, false), corners_of(m.xyz, m.triangles, true));
}

TEST_F(IoStlWriter, AsciiRoundTrip) {
  const TestMesh m = octahedron(1e-3);
  const fs::path path = dir_ / "mesh.stl";
  g2s::write_mesh(path, m.xyz, m.triangles, g2s::MeshFormat::stl_ascii);
  const std::string text = file_bytes(path);
  EXPECT_EQ(text.substr(0, 10), "solid g2s\n");
  EXPECT_EQ(text.substr(text.size() - 13), "endsolid g2s\n");
  EXPECT_NE(text.find("facet normal 0 0 0\n"), std::string::npos) << "degenerate facet";
  const g2s::IndexedMesh back = g2s::read_mesh(path);
  EXPECT_EQ(back.vertex_count(), 6u);
  EXPECT_EQ(corners_of(back.xyz, back.triangles, false), corners_of(m.xyz, m.triangles, true));
}

TEST_F(IoStlWriter, StreamedWriterCountsAndUnfinishedLeavesNothing) {
  const double a[3] = {0, 0, 0};
  const double b[3] = {1, 0, 0};
  const double c[3] = {0, 1, 0};
  {
    g2s::StlWriter writer(dir_ / "a.stl", false);
    for (int i = 0; i < 30000; ++i) writer.add(a, b, c);  // more than the 1 MiB buffer
    EXPECT_EQ(writer.triangles(), 30000u);
    writer.finish();
  }
  EXPECT_EQ(g2s::read_mesh(dir_ / "a.stl").triangles.size(), 30000u);
  {
    g2s::StlWriter writer(dir_ / "b.stl", true);
    writer.add(a, b, c);
    // destroyed without finish(): as if an exception went by
  }
  EXPECT_EQ(entries(), std::vector<std::string>{"a.stl"});
}

TEST_F(IoStlWriter, EmptyMesh) {
  g2s::write_mesh(dir_ / "e.stl", {}, {}, g2s::MeshFormat::stl_binary);
  EXPECT_EQ(fs::file_size(dir_ / "e.stl"), 84u);
  EXPECT_EQ(g2s::read_mesh(dir_ / "e.stl").triangles.size(), 0u);
  g2s::write_mesh(dir_ / "e2.stl", {}, {}, g2s::MeshFormat::stl_ascii);
  EXPECT_EQ(g2s::read_mesh(dir_ / "e2.stl").triangles.size(), 0u);
}

// ---- PLY ----

class IoPlyWriter : public IoWriteDir {};

TEST_F(IoPlyWriter, FloatMeshRoundTripWritesOnlyUsedVerticesInFirstUseOrder) {
  const TestMesh m = octahedron();
  const fs::path path = dir_ / "mesh.ply";
  g2s::write_mesh(path, m.xyz, m.triangles, g2s::MeshFormat::ply_binary);
  const std::string bytes = file_bytes(path);
  EXPECT_NE(bytes.find("format binary_little_endian 1.0\n"), std::string::npos);
  EXPECT_NE(bytes.find("element vertex 6\nproperty float x\n"), std::string::npos);
  EXPECT_NE(bytes.find("property list uchar uint vertex_indices\n"), std::string::npos);
  const g2s::IndexedMesh back = g2s::read_mesh(path);
  ASSERT_EQ(back.vertex_count(), 6u);
  // First use: 1, 3, 5, 2, 4, 6.
  EXPECT_EQ(back.xyz,
            (std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1.5, -1, 0, 0, 0, -1, 0, 0, 0, -1.5}));
  EXPECT_EQ(back.triangles[0], (g2s::Triangle{0, 1, 2}));
  EXPECT_EQ(corners_of(back.xyz, back.triangles, false), corners_of(m.xyz, m.triangles, false));
  // The welded positions read as points too.
  EXPECT_EQ(g2s::read_points(path).size(), 6u);
}

TEST_F(IoPlyWriter, DoubleWhenFloatWouldLoseBits) {
  const TestMesh m = octahedron(4.2e6 + 0.1);  // georeferenced: float cannot hold these
  const fs::path path = dir_ / "geo.ply";
  g2s::write_mesh(path, m.xyz, m.triangles, g2s::MeshFormat::ply_binary);
  EXPECT_NE(file_bytes(path).find("property double x\n"), std::string::npos);
  const g2s::IndexedMesh back = g2s::read_mesh(path);
  EXPECT_EQ(corners_of(back.xyz, back.triangles, false), corners_of(m.xyz, m.triangles, false));
}

TEST_F(IoPlyWriter, BadIndexIsAnInternalErrorAndWritesNothing) {
  const std::vector<double> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<g2s::Triangle> triangles = {{0, 1, 3}};
  for (auto format : {g2s::MeshFormat::ply_binary, g2s::MeshFormat::stl_binary}) {
    expect_error([&] { g2s::write_mesh(dir_ / "bad.ply", xyz, triangles, format); }, Exit::failure,
                 {"bad.ply", "point 3"});
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(IoPlyWriter, MeshFormatFor) {
  EXPECT_EQ(g2s::mesh_format_for("a.ply", false), g2s::MeshFormat::ply_binary);
  EXPECT_EQ(g2s::mesh_format_for("dir.x/A.PLY", true), g2s::MeshFormat::ply_binary);
  EXPECT_EQ(g2s::mesh_format_for("a.Ply", false), g2s::MeshFormat::ply_binary);
  EXPECT_EQ(g2s::mesh_format_for("a.stl", false), g2s::MeshFormat::stl_binary);
  EXPECT_EQ(g2s::mesh_format_for("a.stl", true), g2s::MeshFormat::stl_ascii);
  EXPECT_EQ(g2s::mesh_format_for("noext", false), g2s::MeshFormat::stl_binary);
  EXPECT_EQ(g2s::mesh_format_for("a.ply.stl", true), g2s::MeshFormat::stl_ascii);
}

TEST_F(IoPlyWriter, PointWriterRoundTrip) {
  const fs::path path = dir_ / "points.ply";
  g2s::PlyPointWriter writer(path, 100000);
  for (int i = 0; i < 100000; ++i) {
    writer.add(static_cast<float>(i) * 0.5f, -static_cast<float>(i), 0.25f);
  }
  EXPECT_FALSE(fs::exists(path)) << "visible before finish()";
  writer.finish();
  g2s::ReadReport report;
  const g2s::PointCloud cloud = g2s::read_points(path, &report);
  EXPECT_EQ(report.format, "ply-binary-le");
  ASSERT_EQ(cloud.size(), 100000u);
  EXPECT_EQ(cloud.xyz[3 * 777], 388.5);
  EXPECT_EQ(cloud.xyz[3 * 777 + 1], -777.0);
  EXPECT_EQ(cloud.xyz[3 * 777 + 2], 0.25);
}

TEST_F(IoPlyWriter, PointWriterWrongCountFailsAndLeavesNothing) {
  {
    g2s::PlyPointWriter writer(dir_ / "few.ply", 3);
    writer.add(1, 2, 3);
    expect_error([&] { writer.finish(); }, Exit::failure, {"few.ply", "1 points", "declares 3"});
  }
  {
    g2s::PlyPointWriter writer(dir_ / "many.ply", 1);
    writer.add(1, 2, 3);
    writer.add(1, 2, 3);
    expect_error([&] { writer.finish(); }, Exit::failure, {"many.ply", "2 points", "declares 1"});
  }
  EXPECT_TRUE(entries().empty());
}

// ---- AtomicFile ----

class IoAtomicFile : public IoWriteDir {};

TEST_F(IoAtomicFile, AppearsOnlyAtCommit) {
  const fs::path target = dir_ / "out.bin";
  g2s::AtomicFile file(target);
  EXPECT_EQ(file.target(), target);
  EXPECT_EQ(file.temporary().parent_path(), dir_);
  EXPECT_TRUE(file.temporary().filename().string().starts_with(".out.bin.tmp-"));
  file.write("hello", 5);
  EXPECT_EQ(file.size(), 5u);
  EXPECT_FALSE(fs::exists(target));
  file.commit();
  EXPECT_EQ(file_bytes(target), "hello");
  EXPECT_FALSE(fs::exists(file.temporary()));
  EXPECT_EQ(entries(), std::vector<std::string>{"out.bin"});
}

TEST_F(IoAtomicFile, ReplacesAnExistingFile) {
  const fs::path target = dir_ / "out.bin";
  std::ofstream(target) << "old content";
  g2s::AtomicFile file(target);
  file.write("new", 3);
  EXPECT_EQ(file_bytes(target), "old content");
  file.commit();
  EXPECT_EQ(file_bytes(target), "new");
}

// With write_behind(), the same bytes: full buffers are written on another thread, and write_at
// and read_at wait for them.
TEST_F(IoAtomicFile, WriteAtPatchesFlushedAndBufferedBytes) {
  for (const bool behind : {false, true}) {
    SCOPED_TRACE(behind ? "write behind" : "on the caller's thread");
    const fs::path target = dir_ / "patch.bin";
    std::string expected;
    {
      g2s::AtomicFile file(target);
      if (behind) file.write_behind();
      const std::string block(1000, 'a');
      for (int i = 0; i < 1500; ++i) {  // 1.5 MB in small writes: part flushed, part buffered
        file.write(block.data(), block.size());
        expected += block;
      }
      const std::string big(3 << 20, 'b');  // a block larger than the buffer
      file.write(big.data(), big.size());
      expected += big;
      for (int i = 0; i < 2500; ++i) {  // 2.5 MB more: buffers handed over while one is written
        const std::string line = fmt::format("{:09}\n", i);
        file.write(line.data(), line.size());
        expected += line;
      }
      file.write("tail", 4);
      expected += "tail";
      ASSERT_EQ(file.size(), expected.size());
      const auto patch = [&](std::uint64_t at, std::string_view s) {
        file.write_at(at, s.data(), s.size());
        expected.replace(at, s.size(), s);
      };
      patch(0, "HEAD");                      // long flushed
      patch((1u << 20) - 2, "SPAN");         // across the first flush
      patch(expected.size() - 6, "XXYYZZ");  // the last bytes, partly still buffered
      EXPECT_THROW(file.write_at(expected.size() - 1, "ab", 2), g2s::Error);
      file.flush();
      std::string back(expected.size(), '\0');
      file.read_at(0, back.data(), back.size());
      EXPECT_EQ(back, expected);
      file.commit();
      EXPECT_GE(file.write_behind_cpu_seconds(), 0.0);
    }
    EXPECT_EQ(file_bytes(target), expected);
  }
}

TEST_F(IoAtomicFile, UncommittedFileRemovesItsTemporary) {
  fs::path temporary;
  {
    g2s::AtomicFile file(dir_ / "gone.bin");
    temporary = file.temporary();
    const std::string big(2 << 20, 'x');
    file.write(big.data(), big.size());
    EXPECT_TRUE(fs::exists(temporary));
  }
  EXPECT_FALSE(fs::exists(temporary));
  EXPECT_TRUE(entries().empty());
}

TEST_F(IoAtomicFile, MissingFolder) {
  const fs::path target = dir_ / "no" / "such" / "out.stl";
  expect_error([&] { g2s::AtomicFile file(target); }, Exit::write_failed,
               {target.string(), std::strerror(ENOENT)});
  const TestMesh m = octahedron();
  expect_error([&] { g2s::write_mesh(target, m.xyz, m.triangles, g2s::MeshFormat::ply_binary); },
               Exit::write_failed, {"out.stl", std::strerror(ENOENT)});
}

TEST_F(IoAtomicFile, PathUnderARegularFile) {
  // Fails even for root, unlike permission checks.
  std::ofstream(dir_ / "file") << "x";
  const fs::path target = dir_ / "file" / "x.stl";
  expect_error([&] { g2s::PlyPointWriter writer(target, 0); }, Exit::write_failed,
               {target.string(), std::strerror(ENOTDIR)});
  expect_error([&] { g2s::StlWriter writer("/etc/passwd/x.stl", false); }, Exit::write_failed,
               {"/etc/passwd/x.stl", std::strerror(ENOTDIR)});
}

TEST_F(IoAtomicFile, TargetIsAFolder) {
  fs::create_directory(dir_ / "folder.stl");
  expect_error([&] { g2s::StlWriter writer(dir_ / "folder.stl", false); }, Exit::write_failed,
               {"folder.stl", std::strerror(EISDIR)});
  expect_error([&] { g2s::AtomicFile file(dir_ / "sub/"); }, Exit::write_failed, {"sub"});
}

TEST_F(IoAtomicFile, ReadOnlyFolder) {
  const fs::path folder = dir_ / "ro";
  fs::create_directory(folder);
  fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec);
  g2s::test_support::open_to_others(dir_);
  EXPECT_EQ(g2s::test_support::as_unprivileged([&] {
              return g2s::test_support::error_mismatch(
                  [&] { g2s::AtomicFile file(folder / "out.stl"); }, Exit::write_failed,
                  {"out.stl", std::strerror(EACCES)});
            }),
            "");
  fs::permissions(folder, fs::perms::owner_all);
  EXPECT_TRUE(fs::is_empty(folder));
}

// Runs `body` in a child process whose files may not grow past `limit` bytes (SIGXFSZ ignored,
// so writes fail with EFBIG, as on a full disk). The child exits 0 when body() threw
// Error(write_failed) naming `target` and the OS reason.
template <typename F>
int run_with_file_size_limit(rlim_t limit, const fs::path& target, F&& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    struct rlimit rl {};
    rl.rlim_cur = limit;
    rl.rlim_max = limit;
    if (::setrlimit(RLIMIT_FSIZE, &rl) != 0) ::_exit(20);
    int code = 10;  // no exception
    try {
      body();
    } catch (const g2s::Error& e) {
      const std::string_view what = e.what();
      code = e.code() != Exit::write_failed                              ? 11
             : what.find(target.string()) == std::string_view::npos      ? 12
             : what.find(std::strerror(EFBIG)) == std::string_view::npos ? 13
                                                                         : 0;
    } catch (...) {
      code = 14;
    }
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 100 + WTERMSIG(status);
}

TEST_F(IoAtomicFile, DiskFullLeavesNothing) {
  const fs::path stl = dir_ / "full.stl";
  EXPECT_EQ(run_with_file_size_limit(256 << 10, stl,
                                     [&] {
                                       const double a[3] = {0, 0, 0};
                                       const double b[3] = {1, 0, 0};
                                       const double c[3] = {0, 1, 0};
                                       g2s::StlWriter writer(stl, false);
                                       for (int i = 0; i < 100000; ++i) writer.add(a, b, c);
                                       writer.finish();
                                     }),
            0);
  // Fails only in commit()'s final flush: the whole file fits in the buffer.
  const fs::path ply = dir_ / "full.ply";
  EXPECT_EQ(run_with_file_size_limit(4 << 10, ply,
                                     [&] {
                                       g2s::PlyPointWriter writer(ply, 10000);
                                       for (int i = 0; i < 10000; ++i) writer.add(1, 2, 3);
                                       writer.finish();
                                     }),
            0);
  // Written behind: the failure comes from the writing thread and surfaces on the caller's.
  const fs::path behind = dir_ / "behind.bin";
  EXPECT_EQ(run_with_file_size_limit(256 << 10, behind,
                                     [&] {
                                       g2s::AtomicFile file(behind);
                                       file.write_behind();
                                       const std::string line(50, 'x');
                                       for (int i = 0; i < 100000; ++i) {
                                         file.write(line.data(), line.size());
                                       }
                                       file.commit();
                                     }),
            0);
  EXPECT_TRUE(entries().empty()) << "target or temporary left behind";
}

}  // namespace
