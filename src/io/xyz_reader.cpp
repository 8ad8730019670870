// Text point reader (XYZ, PTS, TXT, CSV): one point per line, space/tab/comma separated, extra
// columns ignored, '#' and '//' comments and blank lines skipped, a leading PTS count line or a
// CSV column-name line skipped (a PTS count must match the points that follow). Decimal commas
// ("1,5 2,5 3,5") are refused: read as separators they would give other numbers. Large files are
// cut at line ends and parsed in parallel (TBB): all at once when collecting, a batch of chunks at
// a time when streaming to a sink (so memory holds one batch whatever the file size).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s::io {
namespace {

struct Chunk {
  std::string_view text;
  std::vector<double> xyz;
  std::uint64_t non_finite = 0;
  std::uint64_t lines = 0;  // lines parsed (all of them unless an error stopped the chunk)
  bool failed = false;
  std::string error;  // message without "<file>: line N: "
};

inline bool is_comment_or_blank(const char* p, const char* end) {
  while (p != end && is_blank(*p)) ++p;
  if (p == end || *p == '#') return true;
  return *p == '/' && p + 1 != end && p[1] == '/';
}

inline bool is_separator(char c) {
  return c == ',' || is_blank(c);
}

// Reads the next field of a data line: skips blanks, takes text up to a blank or comma, then
// consumes blanks and at most one comma. Returns false at the end of the line.
inline bool next_field(const char*& p, const char* end, std::string_view& field) {
  while (p != end && is_blank(*p)) ++p;
  if (p == end) return false;
  const char* start = p;
  while (p != end && !is_separator(*p)) ++p;
  field = std::string_view(start, static_cast<std::size_t>(p - start));
  while (p != end && is_blank(*p)) ++p;
  if (p != end && *p == ',') ++p;
  return true;
}

// Parses one data line into xyz; returns an error message or an empty string.
inline bool parse_line(const char* p, const char* end, double out[3], std::string& error) {
  std::string_view field;
  for (int k = 0; k < 3; ++k) {
    if (!next_field(p, end, field)) {
      error = fmt::format("expected at least 3 numbers (x y z), found {}", k);
      return false;
    }
    if (!parse_number(field, out[k])) {
      error = field.empty() ? fmt::format("column {} is empty (expected a number)", k + 1)
                            : fmt::format("column {}: expected a number, found {}", k + 1,
                                          quote_bad_number(field));
      return false;
    }
  }
  return true;
}

void parse_chunk(Chunk& chunk) {
  const char* p = chunk.text.data();
  const char* const end = p + chunk.text.size();
  chunk.xyz.reserve(chunk.text.size() / 16 * 3);
  while (p != end) {
    const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
    const char* line_end = nl ? static_cast<const char*>(nl) : end;
    ++chunk.lines;
    if (!is_comment_or_blank(p, line_end)) {
      double v[3];
      if (!parse_line(p, line_end, v, chunk.error)) {
        chunk.failed = true;
        return;
      }
      if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) {
        chunk.xyz.insert(chunk.xyz.end(), v, v + 3);
      } else {
        ++chunk.non_finite;
      }
    }
    p = nl ? line_end + 1 : end;
  }
}

// "100,468 198,797 349,983": fields separated by blanks, with a comma between two digits
// inside a field. Read as CSV that would be six numbers, the first three taken as x, y, z.
bool has_decimal_commas(std::string_view line) {
  bool blank_between = false;
  bool tight_comma = false;
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  for (std::size_t i = 1; i + 1 < line.size(); ++i) {
    if (is_blank(line[i]) && !is_separator(line[i - 1]) && !is_blank(line[i + 1]) &&
        line[i + 1] != ',') {
      blank_between = true;
    }
    if (line[i] == ',' && digit(line[i - 1]) && digit(line[i + 1])) tight_comma = true;
  }
  return blank_between && tight_comma;
}

}  // namespace

PointCloud read_xyz_points(const MappedFile& file, ReadReport& report, const RunSink* sink) {
  report.format = "xyz";
  report.declared = 0;
  std::string_view text = file.view();
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  // Classic Mac OS text ends its lines with CR alone: read as one line it would give one point
  // and ignore the rest as extra columns. A file with CRs and no LF at all is read from a copy
  // with LF line ends (of the same length, so file offsets stay as they are).
  std::string lf_copy;
  if (text.find('\r') != std::string_view::npos && text.find('\n') == std::string_view::npos) {
    lf_copy.assign(text);
    std::replace(lf_copy.begin(), lf_copy.end(), '\r', '\n');
    text = lf_copy;
  }

  // The first data line may be a PTS point count or a CSV line of column names.
  std::uint64_t line_before = 0;
  std::optional<std::uint64_t> declared_count;
  {
    LineCursor lines(text, 0, 0);
    std::string_view line;
    while (lines.next(line)) {
      if (is_comment_or_blank(line.data(), line.data() + line.size())) continue;
      const char* p = line.data();
      const char* end = p + line.size();
      std::string_view first;
      std::string_view second;
      next_field(p, end, first);
      const bool single = !next_field(p, end, second);
      std::uint64_t count = 0;
      double number = 0;
      const bool count_line = single && parse_number(first, count);
      const bool names_line = !parse_number(first, number) && !first.empty() &&
                              ((first[0] >= 'A' && first[0] <= 'Z') ||
                               (first[0] >= 'a' && first[0] <= 'z') || first[0] == '"');
      if (count_line || names_line) {
        text.remove_prefix(lines.position());
        line_before = lines.line();
        if (count_line) declared_count = count;
      } else if (has_decimal_commas(line)) {
        fail_input(file.name(),
                   "line {}: {} has a comma between digits in fields separated by blanks: "
                   "decimal commas? g2s reads '.' as the decimal point and ',' as a separator "
                   "(convert the commas to points)",
                   lines.line(), quote_token(line));
      }
      break;
    }
  }

  // Cut into chunks at line ends; parse a batch of them in parallel, then take their points in
  // order. Collecting parses every chunk in one batch.
  constexpr std::size_t kChunk = 4u << 20;
  constexpr std::size_t kStreamBatch = 8;
  std::vector<Chunk> chunks;  // collecting: all of them, concatenated at the end
  std::uint64_t line = line_before;
  std::size_t pos = 0;
  const std::size_t text_start = file.size() - text.size();
  while (pos < text.size()) {
    chunks.clear();
    while (pos < text.size() && (sink == nullptr || chunks.size() < kStreamBatch)) {
      std::size_t cut = std::min(text.size(), pos + kChunk);
      if (cut < text.size()) {
        const void* nl = std::memchr(text.data() + cut, '\n', text.size() - cut);
        cut = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - text.data()) + 1
                 : text.size();
      }
      Chunk c;
      c.text = text.substr(pos, cut - pos);
      chunks.push_back(std::move(c));
      pos = cut;
    }
    if (chunks.size() == 1) {
      parse_chunk(chunks[0]);
    } else {
      tbb::parallel_for(std::size_t{0}, chunks.size(),
                        [&](std::size_t i) { parse_chunk(chunks[i]); });
    }
    for (Chunk& c : chunks) {
      if (c.failed) fail_input(file.name(), "line {}: {}", line + c.lines, c.error);
      line += c.lines;
      report.non_finite += c.non_finite;
      report.points += c.xyz.size() / 3;
      if (sink != nullptr && !c.xyz.empty()) (*sink)(c.xyz);
    }
    file.release_before(text_start + pos);
  }

  if (declared_count && *declared_count != report.points + report.non_finite) {
    fail_input(file.name(),
               "the count line (line {}) says {} points, the file holds {} (truncated, or not "
               "a PTS count?)",
               line_before, *declared_count, report.points + report.non_finite);
  }
  report.declared = declared_count.value_or(0);

  PointCloud cloud;
  if (sink != nullptr) return cloud;
  if (chunks.size() == 1) {
    cloud.xyz = std::move(chunks[0].xyz);
  } else if (chunks.size() > 1) {
    std::vector<std::size_t> offset(chunks.size() + 1, 0);
    for (std::size_t i = 0; i < chunks.size(); ++i) {
      offset[i + 1] = offset[i] + chunks[i].xyz.size();
    }
    cloud.xyz.resize(offset.back());
    tbb::parallel_for(std::size_t{0}, chunks.size(), [&](std::size_t i) {
      std::memcpy(cloud.xyz.data() + offset[i], chunks[i].xyz.data(),
                  chunks[i].xyz.size() * sizeof(double));
      std::vector<double>().swap(chunks[i].xyz);
    });
  }
  return cloud;
}

}  // namespace g2s::io
