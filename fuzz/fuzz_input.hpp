// Shared by the libFuzzer targets: the fuzz input as a reader's file, and the contract every
// reader keeps on any bytes: return, or throw g2s::Error(bad_input). Anything else (a crash, a
// sanitizer report, another exception or exit code) is a bug the fuzzer reports.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "g2s/error.hpp"
#include "io/mapped_file.hpp"

namespace g2s::fuzz {

// The input as an in-memory file: an exactly sized heap copy, so AddressSanitizer sees a read
// one byte past the end.
inline io::MappedFile as_file(const std::uint8_t* data, std::size_t size) {
  return io::MappedFile("fuzz-input", {reinterpret_cast<const char*>(data), size});
}

template <typename Read>
int expect_clean_refusal(Read&& read) {
  try {
    read();
  } catch (const Error& e) {
    if (e.code() != Exit::bad_input) std::abort();  // bad input must be reported as such
  }
  return 0;
}

}  // namespace g2s::fuzz
