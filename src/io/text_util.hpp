// Small shared helpers for the readers: error messages in the "<file>: <place>: <what>" form,
// std::from_chars number parsing that also takes a leading '+', whitespace tokenizing, and
// quoting of bad tokens for messages. Header-only so the hot loops inline them.
#pragma once

#include <fmt/core.h>

#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>

#include "g2s/error.hpp"

namespace g2s::io {

template <typename... Args>
[[noreturn]] void fail_input(const std::string& file, fmt::format_string<Args...> format,
                             Args&&... args) {
  throw Error(Exit::bad_input, file + ": " + fmt::format(format, std::forward<Args>(args)...));
}

inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

// Parses the whole of `token` as a number (decimal, exponent, inf, nan; '+' allowed).
template <typename T>
inline bool parse_number(std::string_view token, T& value) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (first != last && *first == '+') ++first;
  const auto result = std::from_chars(first, last, value);
  return result.ec == std::errc() && result.ptr == last && first != last;
}

inline bool parse_integer(std::string_view token, std::int64_t& value) {
  return parse_number(token, value);
}

// A token as shown in a message: quoted, shortened, non-printable bytes escaped.
inline std::string quote_token(std::string_view token) {
  std::string out = "'";
  const std::size_t limit = 40;
  for (std::size_t i = 0; i < token.size() && i < limit; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += fmt::format("\\x{:02x}", c);
    }
  }
  if (token.size() > limit) out += "...";
  out += "'";
  return out;
}

// A token that is not a number, as shown in a message: quoted, and said to be out of double's
// range when it is a number too large or too small for one ("1e400").
inline std::string quote_bad_number(std::string_view token) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (first != last && *first == '+') ++first;
  double value = 0;
  const auto result = std::from_chars(first, last, value);
  if (result.ec == std::errc::result_out_of_range && result.ptr == last) {
    return quote_token(token) + " (a number beyond the range of double, about 1e-308 to 1e308)";
  }
  return quote_token(token);
}

// Splits a line into whitespace-separated tokens (appends to `tokens`, which is cleared first).
template <typename Vec>
inline void split_blanks(std::string_view line, Vec& tokens) {
  tokens.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && is_blank(line[i])) ++i;
    if (i == n) break;
    const std::size_t start = i;
    while (i < n && !is_blank(line[i])) ++i;
    tokens.push_back(line.substr(start, i - start));
  }
}

// Iterates the lines of a text buffer (without the '\n'; a trailing '\r' is removed) and
// counts them from 1.
class LineCursor {
 public:
  LineCursor(std::string_view data, std::size_t pos, std::uint64_t line_before)
      : data_(data), pos_(pos), line_(line_before) {}

  bool next(std::string_view& line) {
    if (pos_ >= data_.size()) return false;
    const char* begin = data_.data() + pos_;
    const std::size_t left = data_.size() - pos_;
    const void* nl = std::char_traits<char>::find(begin, left, '\n');
    std::size_t len = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - begin) : left;
    pos_ += nl ? len + 1 : len;
    if (len > 0 && begin[len - 1] == '\r') --len;
    ++line_;
    line = std::string_view(begin, len);
    return true;
  }

  // Next line holding something other than blanks.
  bool next_nonblank(std::string_view& line) {
    while (next(line)) {
      for (char c : line) {
        if (!is_blank(c)) return true;
      }
    }
    return false;
  }

  // Whether anything but blanks and line ends is left.
  bool has_nonblank() const {
    for (std::size_t p = pos_; p < data_.size(); ++p) {
      if (!is_blank(data_[p]) && data_[p] != '\n' && data_[p] != '\r') return true;
    }
    return false;
  }
  std::uint64_t line() const { return line_; }  // number of the line last returned
  std::size_t position() const { return pos_; }

 private:
  std::string_view data_;
  std::size_t pos_;
  std::uint64_t line_;
};

}  // namespace g2s::io
