// Test support shared by every test file: the `g2s` CLI run as users run it, the real scans'
// folder, and numbers read from the CLI's JSON where a missing key fails the test.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

namespace g2s::test_support {

// What a CLI run gave: its exit code (-1 when killed by a signal), stdout and stderr.
struct CliRun {
  int code = -1;
  std::string out;
  std::string err;
};

inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs `g2s ARGS` through bash in folder `dir` (ARGS is shell text: quote paths). `prefix` runs
// first in the same bash (e.g. ulimit -f); `wrapper` goes in front of the CLI's path (e.g. setpriv
// to run it as another user). stdout and stderr are kept in dir/cli-stdout.txt and
// dir/cli-stderr.txt.
inline CliRun run_cli(const std::string& args, const std::filesystem::path& dir,
                      const std::string& prefix = "", const std::string& wrapper = "") {
  const std::string command = "cd \"" + dir.string() + "\" && bash -c '" + prefix + " exec " +
                              wrapper + " \"" + G2S_CLI_PATH + "\" " + args +
                              "' > cli-stdout.txt 2> cli-stderr.txt";
  const int status = std::system(command.c_str());
  CliRun run;
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = read_text(dir / "cli-stdout.txt");
  run.err = read_text(dir / "cli-stderr.txt");
  return run;
}

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
