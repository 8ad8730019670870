// Test support: permission checks mean nothing to root, who reads and writes anything. A check
// run through as_unprivileged runs in a forked child that, when the suite runs as root (CI),
// first becomes user nobody, so permission tests run everywhere instead of skipping.
#pragma once

#include <grp.h>
#include <pwd.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>
#include <string_view>

#include "g2s/error.hpp"
#include "support/run_with_deadline.hpp"

namespace g2s::test_support {

// Lets every user through `folder` (and read what it holds by name), so nobody reaches the
// files a test made there.
inline void open_to_others(const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  fs::permissions(folder,
                  fs::perms::others_read | fs::perms::others_exec | fs::perms::group_read |
                      fs::perms::group_exec,
                  fs::perm_options::add);
}

// Runs check() in a child, as user nobody when this process is root; returns its failure
// message, "" on success.
inline std::string as_unprivileged(const std::function<std::string()>& check) {
  return run_with_deadline(60.0, [&]() -> std::string {
    if (::geteuid() == 0) {
      const passwd* nobody = ::getpwnam("nobody");
      if (nobody == nullptr) return "no user nobody to run the permission test as";
      if (::setgroups(0, nullptr) != 0 || ::setgid(nobody->pw_gid) != 0 ||
          ::setuid(nobody->pw_uid) != 0) {
        return "could not become user nobody";
      }
    }
    return check();
  });
}

// What is wrong with how f() failed, "" when it threw Error(code) with every part in its message
// (for checks in a child process, where gtest's assertions do not reach the parent).
template <typename F>
std::string error_mismatch(F&& f, Exit code, std::initializer_list<std::string_view> parts) {
  try {
    f();
  } catch (const Error& e) {
    const std::string message = e.what();
    if (e.code() != code) return "wrong exit code for: " + message;
    for (std::string_view part : parts) {
      if (message.find(part) == std::string::npos) {
        return "message \"" + message + "\" lacks \"" + std::string(part) + "\"";
      }
    }
    return "";
  }
  return "no error thrown";
}

}  // namespace g2s::test_support
