// One error type for the whole library: a message that names the file and the place, and the
// process exit code the CLI returns for it. Documented in README.md ("Exit codes").
#pragma once

#include <stdexcept>
#include <string>

namespace g2s {

enum class Exit : int {
  ok = 0,
  failure = 1,        // internal error: a bug, please report
  usage = 2,          // bad command line
  bad_input = 3,      // input missing, unreadable or malformed
  write_failed = 4,   // output could not be written (missing folder, read-only, disk full)
  no_surface = 5,     // input read, but its points cannot form a surface (none usable, all the
                      // same, on a line, too wide for float, or no triangle found)
  interrupted = 130,  // SIGINT/SIGTERM: temporary files removed, no output left behind
};

class Error : public std::runtime_error {
 public:
  Error(Exit code, const std::string& message) : std::runtime_error(message), code_(code) {}
  Exit code() const noexcept { return code_; }

 private:
  Exit code_;
};

}  // namespace g2s
