// Test support: runs a check in a forked child with a deadline, so a hang fails its test instead
// of stalling the whole suite.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <exception>
#include <functional>
#include <string>

namespace g2s::test_support {

// Runs work() in a forked child and returns its failure message, "" on success. A child still
// running after `seconds` is killed and reported, so a hang fails the test instead of stalling
// the suite.
inline std::string run_with_deadline(double seconds, const std::function<std::string()>& work) {
  int fds[2];
  if (pipe(fds) != 0) return "pipe() failed";
  const pid_t pid = fork();
  if (pid < 0) return "fork() failed";
  if (pid == 0) {
    close(fds[0]);
    std::string message;
    try {
      message = work();
    } catch (const std::exception& e) {
      message = std::string("exception: ") + e.what();
    }
    message = message.substr(0, 4000);
    if (!message.empty() && write(fds[1], message.data(), message.size()) < 0) _exit(3);
    _exit(message.empty() ? 0 : 1);
  }
  close(fds[1]);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  bool timed_out = false;
  while (waitpid(pid, &status, WNOHANG) != pid) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      timed_out = true;
      break;
    }
    usleep(2000);
  }
  std::string message;
  char buffer[4096];
  for (ssize_t got; (got = read(fds[0], buffer, sizeof buffer)) > 0;) {
    message.append(buffer, static_cast<std::size_t>(got));
  }
  close(fds[0]);
  if (timed_out) return "did not finish within " + std::to_string(seconds) + " s";
  if (WIFSIGNALED(status)) return "crashed with signal " + std::to_string(WTERMSIG(status));
  if (WEXITSTATUS(status) != 0 && message.empty()) return "child failed";
  return message;
}

}  // namespace g2s::test_support
