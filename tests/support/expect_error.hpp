// Test support: expects a call to throw g2s::Error with the given exit code and a message
// holding every given part.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string_view>

#include "g2s/error.hpp"

namespace g2s::test_support {

template <typename F>
void expect_error(F&& f, g2s::Exit code, std::initializer_list<std::string_view> parts) {
  try {
    f();
    ADD_FAILURE() << "no exception thrown";
  } catch (const g2s::Error& e) {
    EXPECT_EQ(static_cast<int>(e.code()), static_cast<int>(code)) << e.what();
    const std::string_view what = e.what();
    for (std::string_view part : parts) {
      EXPECT_NE(what.find(part), std::string_view::npos)
          << "message: " << what << "\nshould contain: " << part;
    }
  }
}

}  // namespace g2s::test_support
