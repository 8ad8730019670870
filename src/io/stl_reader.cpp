// STL reader: binary (recognised by its size, 84 + 50 * count, never by a "solid" prefix,
// which many binary headers carry) and ASCII. STL repeats every corner, so corners are welded by
// exact float equality through an open-addressing hash on the bit patterns: linear time.
#include <bit>
#include <cstring>
#include <vector>

#include "io/readers.hpp"
#include "io/text_util.hpp"

namespace g2s::io {
namespace {

// Welds float corners: each distinct (x, y, z) bit pattern gets one index, in order of first
// use. -0 is taken as +0 so that equal floats weld.
class Welder {
 public:
  explicit Welder(std::size_t expected) {
    std::size_t capacity = 1024;
    while (capacity < 2 * expected) capacity *= 2;
    table_.assign(capacity, kNoIndex);
    mask_ = capacity - 1;
    keys_.reserve(3 * expected);
  }

  Index add(const float corner[3], const std::string& file) {
    std::uint32_t b[3];
    for (int k = 0; k < 3; ++k) {
      const float v = corner[k] == 0.0f ? 0.0f : corner[k];
      b[k] = std::bit_cast<std::uint32_t>(v);
    }
    std::size_t i = hash(b) & mask_;
    for (;;) {
      const Index v = table_[i];
      if (v == kNoIndex) break;
      const std::uint32_t* key = keys_.data() + 3 * static_cast<std::size_t>(v);
      if (key[0] == b[0] && key[1] == b[1] && key[2] == b[2]) return v;
      i = (i + 1) & mask_;
    }
    const std::size_t count = keys_.size() / 3;
    if (count >= kNoIndex - 1) {
      fail_input(file, "more than {} distinct vertices: too many for a mesh index", kNoIndex - 1);
    }
    const auto index = static_cast<Index>(count);
    keys_.insert(keys_.end(), b, b + 3);
    table_[i] = index;
    if (2 * (count + 1) > table_.size()) grow();
    return index;
  }

  std::vector<double> positions() const {
    std::vector<double> xyz(keys_.size());
    for (std::size_t i = 0; i < keys_.size(); ++i) {
      xyz[i] = static_cast<double>(std::bit_cast<float>(keys_[i]));
    }
    return xyz;
  }

 private:
  static std::uint64_t hash(const std::uint32_t b[3]) {
    std::uint64_t h = (static_cast<std::uint64_t>(b[0]) << 32 | b[1]) * 0x9E3779B97F4A7C15ull;
    h ^= (static_cast<std::uint64_t>(b[2]) + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    return h;
  }

  void grow() {
    std::vector<Index> bigger(table_.size() * 2, kNoIndex);
    const std::size_t mask = bigger.size() - 1;
    const std::size_t count = keys_.size() / 3;
    for (std::size_t v = 0; v < count; ++v) {
      std::size_t i = hash(keys_.data() + 3 * v) & mask;
      while (bigger[i] != kNoIndex) i = (i + 1) & mask;
      bigger[i] = static_cast<Index>(v);
    }
    table_.swap(bigger);
    mask_ = mask;
  }

  std::vector<Index> table_;
  std::vector<std::uint32_t> keys_;
  std::size_t mask_ = 0;
};

bool binary_size_matches(const MappedFile& file, std::uint32_t& count) {
  if (file.size() < 84) return false;
  std::memcpy(&count, file.bytes() + 80, 4);
  if constexpr (std::endian::native == std::endian::big) count = __builtin_bswap32(count);
  return file.size() == 84 + 50 * static_cast<std::uint64_t>(count);
}

// An ASCII STL keyword, in any case: some writers put them in capitals ("FACET NORMAL").
bool is_word(std::string_view token, std::string_view word) {
  return token.size() == word.size() &&
         std::equal(token.begin(), token.end(), word.begin(),
                    [](char a, char b) { return (a >= 'A' && a <= 'Z' ? a - 'A' + 'a' : a) == b; });
}

bool starts_with_solid(std::string_view v) {
  std::size_t i = 0;
  while (i < v.size() && (is_blank(v[i]) || v[i] == '\n')) ++i;
  return is_word(v.substr(i, 5), "solid");
}

// Bytes no ASCII STL holds: a binary STL whose 80-byte header starts with "solid" (many
// exporters write one) shows them in its triangle count and data.
bool holds_binary_bytes(std::string_view v) {
  for (const char c : v) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v') return true;
  }
  return false;
}

IndexedMesh read_binary_stl(const MappedFile& file, std::uint32_t count) {
  Welder welder(count / 2 + 16);
  IndexedMesh mesh;
  mesh.triangles.resize(count);
  const unsigned char* p = file.bytes() + 84;
  for (std::uint32_t t = 0; t < count; ++t, p += 50) {
    float c[9];
    std::memcpy(c, p + 12, sizeof c);
    if constexpr (std::endian::native == std::endian::big) {
      for (float& f : c)
        f = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<std::uint32_t>(f)));
    }
    for (int k = 0; k < 3; ++k) mesh.triangles[t][k] = welder.add(c + 3 * k, file.name());
  }
  mesh.xyz = welder.positions();
  return mesh;
}

// Tokens of an ASCII STL, with the line each starts on.
class StlTokens {
 public:
  explicit StlTokens(std::string_view text) : p_(text.data()), end_(p_ + text.size()) {}

  bool next(std::string_view& token) {
    while (p_ != end_ && (is_blank(*p_) || *p_ == '\n')) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
    if (p_ == end_) return false;
    const char* start = p_;
    while (p_ != end_ && !is_blank(*p_) && *p_ != '\n') ++p_;
    token = std::string_view(start, static_cast<std::size_t>(p_ - start));
    return true;
  }

  void skip_line() {
    while (p_ != end_ && *p_ != '\n') ++p_;
  }

  std::uint64_t line() const { return line_; }

 private:
  const char* p_;
  const char* end_;
  std::uint64_t line_ = 1;
};

IndexedMesh read_ascii_stl(const MappedFile& file) {
  const std::string& name = file.name();
  StlTokens tokens(file.view());
  Welder welder(file.size() / 400 + 16);  // about 250 bytes per facet, half a vertex each
  IndexedMesh mesh;
  std::string_view tok;
  std::uint64_t facets = 0;
  bool in_solid = false;
  std::vector<Index> corners;

  auto expect = [&](std::string_view word, const char* context) {
    if (!tokens.next(tok)) {
      fail_input(name, "line {}: file ends inside {} (expected '{}'; truncated file?)",
                 tokens.line(), context, word);
    }
    if (!is_word(tok, word)) {
      fail_input(name, "line {}: expected '{}' in {}, found {}", tokens.line(), word, context,
                 quote_token(tok));
    }
  };
  auto number = [&](const char* what, float& value) {
    if (!tokens.next(tok)) {
      fail_input(name, "line {}: file ends inside facet {} (truncated file?)", tokens.line(),
                 facets + 1);
    }
    if (!parse_number(tok, value)) {
      fail_input(name, "line {}: facet {}: expected a number for the {}, found {}", tokens.line(),
                 facets + 1, what, quote_bad_number(tok));
    }
  };

  while (tokens.next(tok)) {
    if (!in_solid) {
      if (!is_word(tok, "solid")) {
        fail_input(name, "line {}: expected 'solid' (an ASCII STL), found {}", tokens.line(),
                   quote_token(tok));
      }
      tokens.skip_line();  // the solid's name
      in_solid = true;
      continue;
    }
    if (is_word(tok, "endsolid")) {
      tokens.skip_line();
      in_solid = false;
      continue;
    }
    if (!is_word(tok, "facet")) {
      fail_input(name, "line {}: expected 'facet' or 'endsolid', found {}", tokens.line(),
                 quote_token(tok));
    }
    const std::string context = fmt::format("facet {}", facets + 1);
    expect("normal", context.c_str());
    float ignored = 0.0f;
    for (int k = 0; k < 3; ++k) number("normal", ignored);
    expect("outer", context.c_str());
    expect("loop", context.c_str());
    corners.clear();
    for (;;) {
      if (!tokens.next(tok)) {
        fail_input(name, "line {}: file ends inside facet {} (truncated file?)", tokens.line(),
                   facets + 1);
      }
      if (is_word(tok, "endloop")) break;
      if (!is_word(tok, "vertex")) {
        fail_input(name, "line {}: facet {}: expected 'vertex' or 'endloop', found {}",
                   tokens.line(), facets + 1, quote_token(tok));
      }
      float c[3];
      for (float& v : c) number("vertex", v);
      corners.push_back(welder.add(c, name));
    }
    if (corners.size() < 3) {
      fail_input(name, "line {}: facet {} has {} vertices (expected 3)", tokens.line(), facets + 1,
                 corners.size());
    }
    expect("endfacet", context.c_str());
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
      mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
    }
    ++facets;
  }
  if (in_solid) {
    fail_input(name, "line {}: file ends without 'endsolid' (truncated file?)", tokens.line());
  }
  mesh.xyz = welder.positions();
  return mesh;
}

}  // namespace

IndexedMesh read_stl(const MappedFile& file) {
  std::uint32_t count = 0;
  if (binary_size_matches(file, count)) return read_binary_stl(file, count);
  if (starts_with_solid(file.view()) && !holds_binary_bytes(file.view().substr(0, 1024))) {
    return read_ascii_stl(file);
  }
  if (file.size() < 84) {
    fail_input(file.name(),
               "not a mesh file: {} bytes, too short for a binary STL (84-byte header), and no "
               "'solid' (ASCII STL) or 'ply' (PLY) at the start",
               file.size());
  }
  fail_input(file.name(),
             "not a mesh file: as a binary STL its triangle count {} (at byte 80) needs 84 + 50 * "
             "{} = {} bytes but the file has {}{}; no 'solid' (ASCII STL) or 'ply' (PLY) at the "
             "start either (a 'solid' followed by binary bytes is a binary STL's header)",
             count, count, 84 + 50 * static_cast<std::uint64_t>(count), file.size(),
             file.size() < 84 + 50 * static_cast<std::uint64_t>(count) ? " (truncated?)" : "");
}

}  // namespace g2s::io
