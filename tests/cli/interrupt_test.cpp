// Interrupting the g2s command line leaves nothing behind: SIGINT and SIGTERM while a file is
// being written remove its temporary, leave no target, and exit with code 130.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

namespace {

namespace fs = std::filesystem;

class Interrupt : public ::testing::TestWithParam<int> {};

TEST_P(Interrupt, WhileWritingLeavesNoFileAndExits130) {
  const fs::path dir = fs::temp_directory_path() / ("g2s-interrupt-" + std::to_string(getpid()) +
                                                    "-" + std::to_string(GetParam()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "big.ply").string();
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // 200M points: minutes of writing, so the signal always arrives mid-file.
    execl(G2S_CLI_PATH, "g2s", "synth", "sphere", "--points", "200M", "-o", out.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until the temporary file exists, then interrupt.
  bool started = false;
  for (int i = 0; i < 500 && !started; ++i) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      started |= entry.path().filename().string().find(".tmp-") != std::string::npos;
    }
    if (!started) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(started) << "no temporary file appeared";
  kill(pid, GetParam());
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_TRUE(fs::is_empty(dir)) << "files left in " << dir;
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Signals, Interrupt, ::testing::Values(SIGINT, SIGTERM));

}  // namespace
