// Test support shared by every test file: the `g2s` CLI (G2S_CLI_PATH) run as users run it, in a
// child process with a deadline, the real scans' folder, and numbers read from the CLI's JSON
// where a missing key fails the test.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "support/temp_folder.hpp"

namespace g2s::test_support {

// What a CLI run gave: its exit code (-1 when killed by a signal or the deadline), stdout and
// stderr (with why the run was killed, if it was).
struct CliRun {
  int code = -1;
  std::string out;
  std::string err;
};

struct CliOptions {
  // A run still going after this many seconds is killed and fails the test as a hang.
  double seconds = 600.0;
  // Run as user nobody through setpriv: a root test run checking permissions (the folder and
  // the files the run reads must be open to others).
  bool as_nobody = false;
  // Files the run writes may not grow past this many bytes (0: no limit). SIGXFSZ is ignored,
  // so writes fail with EFBIG, as on a full disk.
  rlim_t file_size_limit = 0;
  // A command the run goes through, with its arguments (program by absolute path), such as
  // /usr/bin/time measuring its peak memory; empty: none.
  std::vector<std::string> prefix;
};

// A copy of the CLI that user nobody can run, made once per test process and removed at its
// end: the build folder may be out of nobody's reach (a checkout under /root, mode 0700).
class NobodyCli {
 public:
  NobodyCli() : folder_("g2s-cli") {
    namespace fs = std::filesystem;
    constexpr fs::perms kOpen = fs::perms::owner_all | fs::perms::group_read |
                                fs::perms::group_exec | fs::perms::others_read |
                                fs::perms::others_exec;
    fs::permissions(folder_.path(), kOpen);
    path_ = (folder_.path() / "g2s").string();
    fs::copy_file(G2S_CLI_PATH, path_);
    fs::permissions(path_, kOpen);
  }
  const std::string& path() const { return path_; }

 private:
  TempFolder folder_;
  std::string path_;
};

inline const std::string& nobody_cli_path() {
  static const NobodyCli cli;
  return cli.path();
}

// `g2s ARGS` started in a child process whose working folder is `dir`. Its stdout and stderr go
// to unnamed temporary files, so the folder holds only what g2s writes there.
//
// g2s is started through `timeout --foreground 0` (no time limit), which forks it from a small
// process and passes signals and the exit status through, as a shell does (g2s's own peak
// memory no longer depends on it: HostileCli.ReportedPeakIsNotTheStartingProcesss).
class CliChild {
 public:
  CliChild(const std::filesystem::path& dir, const std::vector<std::string>& args,
           const CliOptions& options = {})
      : seconds_(options.seconds), out_(std::tmpfile()), err_(std::tmpfile()) {
    if (out_ == nullptr || err_ == nullptr) return;
    // Everything the child needs is made before fork(): the child of a threaded process may
    // not allocate.
    std::vector<char*> argv;
    if (options.as_nobody) {
      for (const char* a : {"setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups"}) {
        argv.push_back(const_cast<char*>(a));
      }
    }
    for (const std::string& a : options.prefix) argv.push_back(const_cast<char*>(a.c_str()));
    const char* cli = options.as_nobody ? nobody_cli_path().c_str() : G2S_CLI_PATH;
    for (const char* a : {"/usr/bin/timeout", "--foreground", "0", cli}) {
      argv.push_back(const_cast<char*>(a));
    }
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const char* program = options.as_nobody ? "/usr/bin/setpriv" : argv.front();
    const int out = ::fileno(out_), err = ::fileno(err_);
    const rlimit limit{options.file_size_limit, options.file_size_limit};
    pid_ = ::fork();
    if (pid_ > 0) ::setpgid(pid_, pid_);  // here too, so the group exists before any kill
    if (pid_ != 0) return;
    // A group of its own, so that a run past its deadline is killed with g2s.
    if (::setpgid(0, 0) != 0 || ::chdir(dir.c_str()) != 0 || ::dup2(out, STDOUT_FILENO) < 0 ||
        ::dup2(err, STDERR_FILENO) < 0) {
      ::_exit(127);
    }
    if (options.file_size_limit > 0) {
      ::signal(SIGXFSZ, SIG_IGN);
      if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(127);
    }
    ::execv(program, argv.data());
    ::_exit(127);
  }
  ~CliChild() {
    if (pid_ > 0 && !ended_) {
      ::kill(-pid_, SIGKILL);
      ::waitpid(pid_, &status_, 0);
    }
    if (out_) std::fclose(out_);
    if (err_) std::fclose(err_);
  }
  CliChild(const CliChild&) = delete;
  CliChild& operator=(const CliChild&) = delete;

  // Whether the run has ended (or never started); does not wait.
  bool ended() {
    if (!ended_ && (pid_ <= 0 || ::waitpid(pid_, &status_, WNOHANG) == pid_)) ended_ = true;
    return ended_;
  }
  void send(int signal_number) const {
    if (pid_ > 0 && !ended_) ::kill(pid_, signal_number);
  }

  // Waits for the end (a run past the deadline is killed and fails the test) and gives its exit
  // code and output.
  CliRun wait() {
    if (pid_ <= 0) {
      ADD_FAILURE() << "could not start g2s";
      return {-1, "", "could not start g2s"};
    }
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds_);
    std::string why;
    while (!ended()) {
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(-pid_, SIGKILL);
        ::waitpid(pid_, &status_, 0);
        ended_ = true;
        ADD_FAILURE() << "g2s did not finish within " << seconds_ << " s (hang?)";
        why = "\n[killed: did not finish within " + std::to_string(seconds_) + " s]";
      }
      ::usleep(2000);
    }
    CliRun run{WIFEXITED(status_) && why.empty() ? WEXITSTATUS(status_) : -1, contents(out_),
               contents(err_) + why};
    if (WIFSIGNALED(status_) && why.empty()) {
      run.err += "\n[killed by signal " + std::to_string(WTERMSIG(status_)) + "]";
    }
    return run;
  }

 private:
  static std::string contents(std::FILE* file) {
    std::string text;
    std::rewind(file);
    char buffer[65536];
    for (std::size_t got; (got = std::fread(buffer, 1, sizeof buffer, file)) > 0;) {
      text.append(buffer, got);
    }
    return text;
  }

  double seconds_;
  std::FILE* out_;
  std::FILE* err_;
  pid_t pid_ = -1;
  int status_ = 0;
  bool ended_ = false;
};

// Runs `g2s ARGS` in folder `dir` to its end (see CliChild).
inline CliRun run_cli(const std::filesystem::path& dir, const std::vector<std::string>& args,
                      const CliOptions& options = {}) {
  return CliChild(dir, args, options).wait();
}

// Runs `g2s ARGS` in folder `dir`, expects exit code `code`, and gives stdout and stderr
// together.
inline std::string cli_output(const std::filesystem::path& dir,
                              const std::vector<std::string>& args, int code) {
  const CliRun run = run_cli(dir, args);
  EXPECT_EQ(run.code, code) << run.err;
  return run.out + run.err;
}

// A fixture whose test runs the CLI in a fresh folder of its own (dir_).
class CliTest : public FolderTest {
 protected:
  // The CLI run in the test's folder, expected to exit with `code`; stdout and stderr together.
  std::string run(const std::vector<std::string>& args, int code) const {
    return cli_output(dir_, args, code);
  }
};

// The real scans: $G2S_DATA_DIR, or ../shared/data beside the repository.
inline std::filesystem::path data_dir() {
  const char* env = std::getenv("G2S_DATA_DIR");
  return env && *env ? std::filesystem::path(env) : std::filesystem::path(G2S_DEFAULT_DATA_DIR);
}

// The number after "key": in a JSON text. A missing key fails the calling test and gives NaN,
// which fails every comparison after it.
inline double json_number(const std::string& json, const std::string& key) {
  const std::string quoted = "\"" + key + "\":";
  const std::size_t at = json.find(quoted);
  if (at == std::string::npos) {
    ADD_FAILURE() << "no key \"" << key << "\" in " << json;
    return std::numeric_limits<double>::quiet_NaN();
  }
  return std::strtod(json.c_str() + at + quoted.size(), nullptr);  // skips the blanks
}

}  // namespace g2s::test_support

// Skips the test, with the reason, when a real scan (or the data folder) is missing.
#define G2S_SKIP_WITHOUT_DATA(path)                                                         \
  do {                                                                                      \
    if (!std::filesystem::exists(path))                                                     \
      GTEST_SKIP() << "real scan " << (path) << " missing (set G2S_DATA_DIR to the scans)"; \
  } while (0)
