// The checks every subcommand runs before it starts work (cli_checks.hpp): an output never
// replaces an input, an output's extension names a format g2s writes, option values are finite
// and in range, and CLI11's messages become one line saying what is valid.
#include "cli_checks.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <system_error>

#include "g2s/error.hpp"

namespace g2s::cli {
namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// Shortest text of a bound: 1000 rather than 1000.000000.
std::string number_text(double value) {
  return fmt::format("{}", value);
}

}  // namespace

void refuse_same_file(std::initializer_list<std::filesystem::path> inputs,
                      const std::filesystem::path& output, const std::string& what) {
  struct stat out {};
  const bool output_exists = ::stat(output.c_str(), &out) == 0;
  for (const std::filesystem::path& input : inputs) {
    struct stat in {};
    if (input.empty()) continue;
    const bool input_exists = ::stat(input.c_str(), &in) == 0;
    // Two paths not there yet (a --keep-store and -o to be written) are the same when they
    // name the same place.
    std::error_code ec;
    const bool same = output_exists
                          ? input_exists && in.st_dev == out.st_dev && in.st_ino == out.st_ino
                          : !input_exists && std::filesystem::weakly_canonical(input, ec) ==
                                                 std::filesystem::weakly_canonical(output, ec);
    if (same) {
      throw Error(Exit::usage,
                  fmt::format("{} {} is the same file as {}, which this run also reads or "
                              "writes: choose another path",
                              what, output.string(), input.string()));
    }
  }
}

MeshFormat checked_mesh_format(const std::filesystem::path& output, bool ascii) {
  const std::string ext = lower_extension(output);
  if (ext == ".ply") {
    if (ascii) {
      throw Error(Exit::usage, fmt::format("-o {}: --ascii applies to STL only; PLY is written "
                                           "binary (use a .stl name for ASCII STL)",
                                           output.string()));
    }
    return MeshFormat::ply_binary;
  }
  if (ext == ".stl") return ascii ? MeshFormat::stl_ascii : MeshFormat::stl_binary;
  throw Error(Exit::usage,
              fmt::format("-o {}: unsupported mesh format '{}'; the output must end in .stl or "
                          ".ply",
                          output.string(), ext.empty() ? "(no extension)" : ext));
}

void require_extension(const std::filesystem::path& output, const std::string& extension,
                       const std::string& what) {
  if (lower_extension(output) == extension) return;
  throw Error(Exit::usage, fmt::format("-o {}: {} is written as {}; the output must end in {}",
                                       output.string(), what, extension.substr(1), extension));
}

CLI::Validator finite_range(double lo, double hi) {
  const std::string valid = fmt::format("a number from {} to {}", number_text(lo), number_text(hi));
  return CLI::Validator(
      [lo, hi, valid](std::string& text) -> std::string {
        double value = 0.0;
        const char* end = text.data() + text.size();
        const auto [stop, ec] = std::from_chars(text.data(), end, value);
        if (ec != std::errc() || stop != end || !std::isfinite(value) || value < lo || value > hi) {
          return fmt::format("'{}' is not valid: expected {}", text, valid);
        }
        return "";
      },
      fmt::format("[{} - {}]", number_text(lo), number_text(hi)));
}

CLI::Validator count_range(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        long long value = 0;
        const char* end = text.data() + text.size();
        const auto [stop, ec] = std::from_chars(text.data(), end, value);
        if (ec != std::errc() || stop != end || value < lo || value > hi) {
          return fmt::format("'{}' is not valid: expected a whole number from {} to {}", text, lo,
                             hi);
        }
        return "";
      },
      fmt::format("[{} - {}]", lo, hi));
}

CLI::Validator unsigned_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const char* end = text.data() + text.size();
        const auto [stop, ec] = std::from_chars(text.data(), end, value);
        if (ec != std::errc() || stop != end) {
          return fmt::format("'{}' is not valid: expected a whole number from 0 to {}", text,
                             std::numeric_limits<std::uint64_t>::max());
        }
        return "";
      },
      "[0 - 2^64-1]");
}

CLI::Validator byte_size() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::string error = fmt::format(
            "'{}' is not valid: expected a size of at least 1M such as 512M or 4G (suffixes K, "
            "M, G, T)",
            text);
        std::string number = text;
        double scale = 1.0;
        // "4GiB", "512MB" and "512mb" read as "4G" and "512M".
        for (const std::string_view unit : {"iB", "ib", "B", "b"}) {
          if (number.size() > unit.size() + 1 && number.ends_with(unit) &&
              std::isalpha(static_cast<unsigned char>(number[number.size() - unit.size() - 1]))) {
            number.resize(number.size() - unit.size());
            break;
          }
        }
        if (!number.empty()) {
          const char suffix =
              static_cast<char>(std::toupper(static_cast<unsigned char>(number.back())));
          const std::string suffixes = "KMGT";
          if (const auto at = suffixes.find(suffix); at != std::string::npos) {
            scale = std::ldexp(1.0, 10 * static_cast<int>(at + 1));
            number.pop_back();
          }
        }
        double value = 0.0;
        const char* end = number.data() + number.size();
        const auto [stop, ec] = std::from_chars(number.data(), end, value);
        if (number.empty() || ec != std::errc() || stop != end || !std::isfinite(value))
          return error;
        const double bytes = value * scale;
        if (!(bytes >= 1048576.0) || bytes > 0x1.0p62) return error;
        text = std::to_string(static_cast<std::uint64_t>(bytes));
        return "";
      },
      "SIZE");
}

void check_radius_steps(const std::vector<double>& steps) {
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (!std::isfinite(steps[i]) || steps[i] <= 0.0 || (i > 0 && steps[i] <= steps[i - 1])) {
      throw Error(Exit::usage,
                  fmt::format("--radius-steps: expected finite positive numbers in increasing "
                              "order (e.g. 1 1.5 2 3), not '{}'",
                              fmt::join(steps, " ")));
    }
  }
}

std::string failure_message(const CLI::App* app, const CLI::Error& error) {
  std::string what = error.what();
  const std::string name = error.get_name();
  if (name == "RequiredError" && app->get_subcommands().empty() && app->get_parent() == nullptr) {
    std::vector<std::string> commands;
    for (const CLI::App* sub : app->get_subcommands({})) commands.push_back(sub->get_name());
    const std::vector<std::string> rest = app->remaining();
    what = rest.empty() ? "no command given" : fmt::format("unknown command '{}'", rest.front());
    what += fmt::format("; the commands are {}", fmt::join(commands, ", "));
  } else if (name == "ExtrasError") {
    what = fmt::format("{} (see --help for the arguments)", what);
  }
  std::replace(what.begin(), what.end(), '\n', ' ');
  return fmt::format("g2s: error: {}\n", what);
}

}  // namespace g2s::cli
