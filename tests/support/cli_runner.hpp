// Test support: runs the real g2s command line (G2S_CLI_PATH) in a child process with its
// stdout and stderr captured in files of `dir`; a run past its deadline is killed and fails the
// test as a hang.
#pragma once

#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "support/temp_folder.hpp"

namespace g2s::test_support {

struct CliRun {
  int exit_code = -1;  // -1: killed by a signal or by the deadline
  std::string out;     // stdout
  std::string err;     // stderr, or why the run failed
};

// as_nobody: run it as user nobody through setpriv (a root test run checking permissions; `dir`
// and the files it reads must be open to others).
inline CliRun run_cli(const std::filesystem::path& dir, const std::vector<std::string>& args,
                      double seconds = 60.0, bool as_nobody = false) {
  const std::filesystem::path out_path = dir / "cli.stdout";
  const std::filesystem::path err_path = dir / "cli.stderr";
  const pid_t pid = fork();
  if (pid < 0) return {-1, "", "fork() failed"};
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0 || dup2(out, STDOUT_FILENO) < 0 || dup2(err, STDERR_FILENO) < 0) {
      _exit(127);
    }
    std::vector<char*> argv;
    if (as_nobody) {
      for (const char* a : {"setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups"}) {
        argv.push_back(const_cast<char*>(a));
      }
    }
    argv.push_back(const_cast<char*>(as_nobody ? G2S_CLI_PATH : "g2s"));
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(as_nobody ? "/usr/bin/setpriv" : G2S_CLI_PATH, argv.data());
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) != pid) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      ADD_FAILURE() << "g2s did not finish within " << seconds << " s (hang?)";
      return {-1, file_bytes(out_path), "timed out"};
    }
    usleep(2000);
  }
  CliRun result{WIFEXITED(status) ? WEXITSTATUS(status) : -1, file_bytes(out_path),
                file_bytes(err_path)};
  if (WIFSIGNALED(status)) result.err += fmt::format("\n[killed by signal {}]", WTERMSIG(status));
  return result;
}

}  // namespace g2s::test_support
