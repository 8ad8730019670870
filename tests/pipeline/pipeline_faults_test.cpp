// Faults in every stage of the pipeline: a full disk while writing the tile store or the mesh,
// and SIGINT/SIGTERM during tile, grow, stitch and mesh, leave no file that looks complete and
// no temporary behind, with exit codes 4 and 130; an interrupted grow resumes where it stopped
// and the result is the same mesh.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
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

  // Runs the CLI through bash in the test folder; `prefix` goes before it (e.g. ulimit).
  int run(const std::string& args, const std::string& prefix = "") const {
    return g2s::test_support::run_cli(args, dir_, prefix).code;
  }

  // Starts the CLI, sends `signal` as soon as `ready()` holds (checked every few ms), returns its
  // exit code (-1: it finished first).
  template <class Ready>
  int interrupt(const std::vector<std::string>& args, int signal, Ready ready) const {
    const pid_t pid = fork();
    if (pid == 0) {
      if (chdir(dir_.c_str()) != 0) _exit(126);
      std::vector<char*> argv{const_cast<char*>("g2s")};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(G2S_CLI_PATH, argv.data());
      _exit(127);
    }
    int status = 0;
    while (!ready()) {
      if (waitpid(pid, &status, WNOHANG) == pid) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(3));
    }
    kill(pid, signal);
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
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

  static std::string read(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  g2s::test_support::TempFolder folder_{"g2s-faults"};
  const fs::path dir_ = folder_.path();
};

// ulimit -f counts 1024-byte blocks; SIGXFSZ is ignored so the write fails with EFBIG instead.
const std::string kSmallDisk = "trap \"\" XFSZ; ulimit -f 256;";

TEST_F(PipelineFaults, FullDiskWhileWritingTheTileStore) {
  make_cloud(200000);  // a 5.6 MB store
  EXPECT_EQ(run("tile cloud.ply s.store", kSmallDisk), 4);
  EXPECT_FALSE(fs::exists(dir_ / "s.store"));
  EXPECT_TRUE(temporaries().empty());
  EXPECT_NE(read(dir_ / "cli-stderr.txt").find("s.store"), std::string::npos);
  // g2s mesh fails at its temporary store and leaves nothing either.
  EXPECT_EQ(run("mesh cloud.ply -o out.stl", kSmallDisk), 4);
  EXPECT_FALSE(fs::exists(dir_ / "out.stl"));
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(PipelineFaults, FullDiskWhileWritingTheMesh) {
  make_cloud(60000);  // 120k triangles: a 6 MB STL, from a 1.7 MB store
  ASSERT_EQ(run("tile cloud.ply s.store --tile-points 20000 -q"), 0);
  ASSERT_EQ(run("grow s.store -q"), 0);
  EXPECT_EQ(run("stitch s.store -o out.stl", "trap \"\" XFSZ; ulimit -f 2048;"), 4);
  EXPECT_FALSE(fs::exists(dir_ / "out.stl"));
  EXPECT_TRUE(temporaries().empty());
  EXPECT_NE(read(dir_ / "cli-stderr.txt").find("out.stl"), std::string::npos);
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
  EXPECT_EQ(
      interrupt({"mesh", "cloud.ply", "-o", "m.stl", "--tile-points", "50000", "--threads", "1"},
                SIGINT, store_made),
      130);
  EXPECT_FALSE(fs::exists(dir_ / "m.stl"));
  EXPECT_TRUE(temporaries().empty());

  ASSERT_EQ(run("tile cloud.ply s.store --tile-points 50000 -q"), 0);
  // grow, one thread: stopped after its first tile; finished tiles stay and are not grown again.
  const fs::path grown = dir_ / "s.store.grown";
  EXPECT_EQ(
      interrupt({"grow", "s.store", "--threads", "1"}, SIGINT, [&] { return files_in(grown) > 0; }),
      130);
  EXPECT_TRUE(temporaries().empty());
  const std::size_t kept = files_in(grown);
  EXPECT_GT(kept, 0u);
  ASSERT_EQ(run("grow s.store"), 0);
  EXPECT_NE(read(dir_ / "cli-stderr.txt").find(fmt::format("({} already there)", kept)),
            std::string::npos)
      << read(dir_ / "cli-stderr.txt");
  // stitch: stopped while it writes the mesh, nothing is left; run again, it gives the mesh of
  // one g2s mesh run.
  const int code = interrupt({"stitch", "s.store", "-o", "s.stl"}, SIGTERM, writing);
  if (code != -1) {  // (it may finish before the signal on a fast machine)
    EXPECT_EQ(code, 130);
    EXPECT_FALSE(fs::exists(dir_ / "s.stl"));
  }
  EXPECT_TRUE(temporaries().empty());
  ASSERT_EQ(run("stitch s.store -o s.stl -q"), 0);
  ASSERT_EQ(run("mesh cloud.ply -o m.stl --tile-points 50000 -q"), 0);
  EXPECT_TRUE(read(dir_ / "s.stl") == read(dir_ / "m.stl"));
}

}  // namespace
