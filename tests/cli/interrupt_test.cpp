// Interrupting the g2s command line leaves nothing behind: SIGINT, SIGTERM, SIGHUP (a closed
// terminal) and SIGQUIT while a file is being written remove its temporary, leave no target, and
// exit with code 130.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "support/cli.hpp"
#include "support/temp_folder.hpp"

namespace {

namespace fs = std::filesystem;

class Interrupt : public ::testing::TestWithParam<int> {};

TEST_P(Interrupt, WhileWritingLeavesNoFileAndExits130) {
  const g2s::test_support::TempFolder folder("g2s-interrupt");
  const fs::path& dir = folder.path();
  const std::string out = (dir / "big.ply").string();
  // 200M points: minutes of writing, so the signal always arrives mid-file.
  g2s::test_support::CliChild child(dir, {"synth", "sphere", "--points", "200M", "-o", out});
  // Wait until the temporary file exists, then interrupt.
  bool started = false;
  for (int i = 0; i < 500 && !started; ++i) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      started |= entry.path().filename().string().find(".tmp-") != std::string::npos;
    }
    if (!started) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(started) << "no temporary file appeared";
  child.send(GetParam());
  const g2s::test_support::CliRun run = child.wait();
  EXPECT_EQ(run.code, 130) << run.err;
  EXPECT_TRUE(fs::is_empty(dir)) << "files left in " << dir;
}

INSTANTIATE_TEST_SUITE_P(Signals, Interrupt, ::testing::Values(SIGINT, SIGTERM, SIGHUP, SIGQUIT));

}  // namespace
