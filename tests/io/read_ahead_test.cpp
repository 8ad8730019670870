// Tests of scan_points_ahead: the same runs in the same order as scan_points, in arenas of one to
// four threads, for binary PLY and text; a reader's error reaches the caller after the runs before
// it; a sink that throws stops the reader and its error is the one the caller gets.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "g2s/error.hpp"
#include "io/readers.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;
using Runs = std::vector<std::vector<double>>;

class ReadAhead : public g2s::test_support::FolderTest {
 protected:
  // A binary PLY of n float points, its body cut to `kept` points (a truncated file) if less.
  // Each vertex also has an empty list, so its rows are walked one by one and a short body is
  // found where it ends, after the runs before it were handed over.
  fs::path binary_ply(const std::string& name, std::size_t n, std::size_t kept) const {
    std::string bytes = fmt::format(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty "
        "float y\nproperty float z\nproperty list uchar int tags\nend_header\n",
        n);
    for (std::size_t i = 0; i < kept; ++i) {
      const float p[3] = {static_cast<float>(i % 1000), static_cast<float>(i / 1000),
                          static_cast<float>(i % 7) * 0.5f};
      bytes.append(reinterpret_cast<const char*>(p), sizeof p);
      bytes.push_back('\0');  // no tags
    }
    return write(name, bytes);
  }
  // A text cloud of n points, past one 4 MiB chunk of the parallel text parser.
  fs::path text_cloud(const std::string& name, std::size_t n) const {
    std::string text;
    for (std::size_t i = 0; i < n; ++i) {
      text += fmt::format("{} {} {}.25\n", i % 1000, i / 1000, i % 11);
    }
    return write(name, text);
  }
  // The runs a reader hands over, and its report.
  template <class Scan>
  static Runs runs_of(Scan&& scan, const fs::path& path, g2s::ReadReport& report) {
    Runs runs;
    scan(
        path, [&](std::span<const double> run) { runs.emplace_back(run.begin(), run.end()); },
        report);
    return runs;
  }
};

TEST_F(ReadAhead, SameRunsAsScanPointsForAnyThreadCount) {
  const fs::path ply = binary_ply("cloud.ply", 300'000, 300'000);  // five runs of 64k points
  const fs::path text = text_cloud("cloud.xyz", 400'000);          // over 4 MiB of text
  for (const fs::path& path : {ply, text}) {
    g2s::ReadReport expected_report;
    const Runs expected = runs_of(g2s::io::scan_points, path, expected_report);
    ASSERT_GT(expected.size(), 1u);
    for (const int threads : {1, 2, 4}) {
      SCOPED_TRACE(fmt::format("{}, {} threads", path.filename().string(), threads));
      g2s::ReadReport report;
      const Runs runs = tbb::task_arena(threads).execute(
          [&] { return runs_of(g2s::io::scan_points_ahead, path, report); });
      EXPECT_EQ(runs, expected);
      EXPECT_EQ(report.points, expected_report.points);
      EXPECT_EQ(report.format, expected_report.format);
      EXPECT_EQ(report.declared, expected_report.declared);
    }
  }
}

// Two readings at once on the two threads of one arena (a library user's parallel loop) both
// finish with their own runs: each reader has an arena of its own, so neither waits for a slot
// that a caller blocked on its runs holds.
TEST_F(ReadAhead, ConcurrentReadingsInOneArenaFinish) {
  const fs::path ply = binary_ply("cloud.ply", 300'000, 300'000);
  const fs::path text = text_cloud("cloud.xyz", 400'000);
  g2s::ReadReport ply_report, text_report;
  const Runs ply_runs = runs_of(g2s::io::scan_points, ply, ply_report);
  const Runs text_runs = runs_of(g2s::io::scan_points, text, text_report);
  Runs got_ply, got_text;
  tbb::task_arena(2).execute([&] {
    tbb::parallel_invoke(
        [&] {
          g2s::ReadReport report;
          got_ply = runs_of(g2s::io::scan_points_ahead, ply, report);
        },
        [&] {
          g2s::ReadReport report;
          got_text = runs_of(g2s::io::scan_points_ahead, text, report);
        });
  });
  EXPECT_EQ(got_ply, ply_runs);
  EXPECT_EQ(got_text, text_runs);
}

TEST_F(ReadAhead, ReadersErrorComesAfterTheRunsBeforeIt) {
  const fs::path path = binary_ply("short.ply", 300'000, 200'000);
  // The first run is taken slowly, so that the reader meets the end of the file (and its
  // error) while the runs before it still wait to be taken.
  const auto scan = [&](auto&& reader, Runs& runs) {
    try {
      g2s::ReadReport report;
      reader(
          path,
          [&](std::span<const double> run) {
            if (runs.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
            runs.emplace_back(run.begin(), run.end());
          },
          report);
    } catch (const g2s::Error& e) {
      EXPECT_EQ(e.code(), g2s::Exit::bad_input);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Runs expected_runs, runs;
  const std::string expected = scan(g2s::io::scan_points, expected_runs);
  EXPECT_NE(expected.find("truncated"), std::string::npos) << expected;
  EXPECT_EQ(expected_runs.size(), 3u);  // 3 runs of 64k points, then the error
  const std::string got =
      tbb::task_arena(2).execute([&] { return scan(g2s::io::scan_points_ahead, runs); });
  EXPECT_EQ(got, expected);
  EXPECT_EQ(runs, expected_runs);
}

TEST_F(ReadAhead, SinkErrorStopsTheReader) {
  const fs::path path = binary_ply("cloud.ply", 1'000'000, 1'000'000);  // 16 runs
  std::size_t calls = 0;
  tbb::task_arena(2).execute([&] {
    g2s::ReadReport report;
    EXPECT_THROW(g2s::io::scan_points_ahead(
                     path,
                     [&](std::span<const double>) {
                       if (++calls == 2) throw std::runtime_error("sink stops");
                     },
                     report),
                 std::runtime_error);
  });
  EXPECT_EQ(calls, 2u);
}

}  // namespace
