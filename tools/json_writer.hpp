// One JSON object, built field by field, for every command's --json output: strings (paths may
// hold quotes, backslashes and control characters) are escaped here and only here.
#pragma once

#include <fmt/format.h>

#include <string>
#include <string_view>
#include <type_traits>

namespace g2s::cli {

// The contents of a JSON string for `text` (without the surrounding quotes).
inline std::string json_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\u{:04x}", static_cast<int>(c));
    } else {
      out += c;
    }
  }
  return out;
}

class JsonObject {
 public:
  JsonObject& text(std::string_view key, std::string_view value) {
    return raw(key, "\"" + json_escape(value) + "\"");
  }
  template <typename Number>
  JsonObject& number(std::string_view key, Number value) {
    if constexpr (std::is_same_v<Number, bool>) return raw(key, value ? "true" : "false");
    return raw(key, fmt::format("{}", value));
  }
  // A number with a fixed count of decimals (timings, megabytes).
  JsonObject& fixed(std::string_view key, double value, int decimals) {
    return raw(key, fmt::format("{:.{}f}", value, decimals));
  }
  // `json` is already JSON (an object or array built elsewhere).
  JsonObject& raw(std::string_view key, std::string_view json) {
    body_ += body_.empty() ? "{" : ",";
    body_ += fmt::format("\"{}\":{}", json_escape(key), json);
    return *this;
  }
  std::string str() const { return body_.empty() ? "{}" : body_ + "}"; }

 private:
  std::string body_;
};

}  // namespace g2s::cli
