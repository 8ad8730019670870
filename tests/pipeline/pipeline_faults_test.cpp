// Faults in every stage of the pipeline: a full disk while writing the tile store or the mesh,
// and SIGINT/SIGTERM during tile, grow, stitch and mesh, leave no file that looks complete and
// no temporary behind, with exit codes 4 and 130; an interrupted grow resumes where it stopped
// and the result is the same mesh.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "g2s/synth.hpp"
#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;

class PipelineFaults : public ::testing::Test {
 protected:
  void make_cloud(std::uint64_t points) const {
    g2s::SynthOptions o;
    o.shape = g2s::SynthShape::torus;
    o.points = points;
    g2s::write_synthetic_cloud(dir_ / "cloud.ply", o);
  }

  // Runs the CLI in the test folder; files it writes may not grow past `file_size_limit` bytes
  // (0: no limit).
  g2s::test_support::CliRun run(const std::vector<std::string>& args,
                                rlim_t file_size_limit = 0) const {
    g2s::test_support::CliOptions options;
    options.file_size_limit = file_size_limit;
    return g2s::test_support::run_cli(dir_, args, options);
  }

  // Starts the CLI, sends `signal` as soon as `ready()` holds (checked every few ms), returns its
  // exit code (-1: it finished first or was killed).
  template <class Ready>
  int interrupt(const std::vector<std::string>& args, int signal, Ready ready) const {
    g2s::test_support::CliChild child(dir_, args);
    while (!ready()) {
      if (child.ended()) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(3));
    }
    child.send(signal);
    return child.wait().code;
  }

  std::size_t files_in(const fs::path& folder) const {
    std::error_code error;
    std::size_t n = 0;
    for (const auto& entry : fs::directory_iterator(folder, error)) {
      n += entry.path().extension() == ".g2sgrow";
    }
    return n;
  }

  // Files in the folder (and the growth folder) whose names mark an unfinished write. Files may
  // come and go while this looks, so errors only end the listing early.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> found;
    for (const fs::path& folder : {dir_, dir_ / "s.store.grown"}) {
      std::error_code error;
      for (fs::directory_iterator it(folder, error), end; !error && it != end;
           it.increment(error)) {
        const std::string name = it->path().filename().string();
        if (name.find(".tmp-") != std::string::npos || name.find(".store-") != std::string::npos) {
          found.push_back(it->path().string());
        }
      }
    }
    return found;
  }

  g2s::test_support::TempFolder folder_{"g2s-faults"};
  const fs::path dir_ = folder_.path();
};

// A disk with room for 256 KiB per file.
constexpr rlim_t kSmallDisk = 256 * 1024;

TEST_F(PipelineFaults, FullDiskWhileWritingTheTileStore) {
  make_cloud(200000);  // a 5.6 MB store
  const g2s::test_support::CliRun tile = run({"tile", "cloud.ply", "s.store"}, kSmallDisk);
  EXPECT_EQ(tile.code, 4) << tile.err;
  EXPECT_FALSE(fs::exists(dir_ / "s.store"));
  EXPECT_TRUE(temporaries().empty());
  EXPECT_NE(tile.err.find("s.store"), std::string::npos) << tile.err;
  // g2s mesh fails at its temporary store and leaves nothing either.
  EXPECT_EQ(run({"mesh", "cloud.ply", "-o", "out.stl"}, kSmallDisk).code, 4);
  EXPECT_FALSE(fs::exists(dir_ / "out.stl"));
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(PipelineFaults, FullDiskWhileWritingTheMesh) {
  make_cloud(60000);  // 120k triangles: a 6 MB STL, from a 1.7 MB store
  ASSERT_EQ(run({"tile", "cloud.ply", "s.store", "--tile-points", "20000", "-q"}).code, 0);
  ASSERT_EQ(run({"grow", "s.store", "-q"}).code, 0);
  const g2s::test_support::CliRun stitch = run({"stitch", "s.store", "-o", "out.stl"}, 2048 * 1024);
  EXPECT_EQ(stitch.code, 4) << stitch.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.stl"));
  EXPECT_TRUE(temporaries().empty());
  EXPECT_NE(stitch.err.find("out.stl"), std::string::npos) << stitch.err;
  // PLY: the 1.9 MB spill of triangles fails first, on its write-behind thread.
  const g2s::test_support::CliRun ply = run({"stitch", "s.store", "-o", "out.ply"}, 1024 * 1024);
  EXPECT_EQ(ply.code, 4) << ply.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.ply"));
  EXPECT_TRUE(temporaries().empty());
  EXPECT_NE(ply.err.find("out.ply"), std::string::npos) << ply.err;
}

TEST_F(PipelineFaults, InterruptedStagesLeaveNothingAndGrowResumes) {
  make_cloud(600000);
  const auto writing = [&] { return !temporaries().empty(); };
  // tile: stopped while writing, neither the store nor its temporary is left.
  for (int signal : {SIGINT, SIGTERM}) {
    EXPECT_EQ(interrupt({"tile", "cloud.ply", "s.store"}, signal, writing), 130);
    EXPECT_FALSE(fs::exists(dir_ / "s.store"));
    EXPECT_TRUE(temporaries().empty());
  }
  // mesh: stopped once its temporary store exists (while meshing): that store is removed too.
  const auto store_made = [&] {
    for (const std::string& path : temporaries()) {
      if (path.find(".store-") != std::string::npos && path.find(".tmp-") == std::string::npos) {
        return true;
      }
    }
    return false;
  };
  // SIGHUP too: a closed terminal or ssh session (it used to leave the store and the spills).
  for (int signal : {SIGINT, SIGHUP}) {
    EXPECT_EQ(
        interrupt({"mesh", "cloud.ply", "-o", "m.stl", "--tile-points", "50000", "--threads", "1"},
                  signal, store_made),
        130);
    EXPECT_FALSE(fs::exists(dir_ / "m.stl"));
    EXPECT_TRUE(temporaries().empty());
  }

  ASSERT_EQ(run({"tile", "cloud.ply", "s.store", "--tile-points", "50000", "-q"}).code, 0);
  // grow, one thread: stopped after its first tile; finished tiles stay and are not grown again.
  const fs::path grown = dir_ / "s.store.grown";
  EXPECT_EQ(
      interrupt({"grow", "s.store", "--threads", "1"}, SIGINT, [&] { return files_in(grown) > 0; }),
      130);
  EXPECT_TRUE(temporaries().empty());
  const std::size_t kept = files_in(grown);
  EXPECT_GT(kept, 0u);
  const g2s::test_support::CliRun regrow = run({"grow", "s.store"});
  ASSERT_EQ(regrow.code, 0) << regrow.err;
  EXPECT_NE(regrow.err.find(fmt::format("({} already there)", kept)), std::string::npos)
      << regrow.err;
  // stitch: stopped while it writes the mesh, nothing is left; run again, it gives the mesh of
  // one g2s mesh run.
  const int code = interrupt({"stitch", "s.store", "-o", "s.stl"}, SIGTERM, writing);
  if (code != -1) {  // (it may finish before the signal on a fast machine)
    EXPECT_EQ(code, 130);
    EXPECT_FALSE(fs::exists(dir_ / "s.stl"));
  }
  EXPECT_TRUE(temporaries().empty());
  ASSERT_EQ(run({"stitch", "s.store", "-o", "s.stl", "-q"}).code, 0);
  ASSERT_EQ(run({"mesh", "cloud.ply", "-o", "m.stl", "--tile-points", "50000", "-q"}).code, 0);
  EXPECT_TRUE(g2s::test_support::file_bytes(dir_ / "s.stl") ==
              g2s::test_support::file_bytes(dir_ / "m.stl"));
}

}  // namespace
