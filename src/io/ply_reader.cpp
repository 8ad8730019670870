// PLY body reader shared by read_points and read_mesh: walks every element of an ascii or
// binary (LE/BE) body in header order, takes the vertex element's x, y, z (any scalar type, any
// position, lists allowed around them) and optionally the face index lists, skips the rest.
// Binary vertices without lists take a fixed-stride loop specialised for float/double. Vertices
// are collected (read_points) or streamed to a sink in runs (scan_points, bounded memory).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

#include "io/ply_format.hpp"
#include "io/text_util.hpp"

namespace g2s::io {
namespace {

inline std::uint16_t byte_swap(std::uint16_t v) {
  return __builtin_bswap16(v);
}
inline std::uint32_t byte_swap(std::uint32_t v) {
  return __builtin_bswap32(v);
}
inline std::uint64_t byte_swap(std::uint64_t v) {
  return __builtin_bswap64(v);
}

template <typename T>
struct UnsignedOf;
template <>
struct UnsignedOf<std::int16_t> {
  using type = std::uint16_t;
};
template <>
struct UnsignedOf<std::uint16_t> {
  using type = std::uint16_t;
};
template <>
struct UnsignedOf<std::int32_t> {
  using type = std::uint32_t;
};
template <>
struct UnsignedOf<std::uint32_t> {
  using type = std::uint32_t;
};
template <>
struct UnsignedOf<float> {
  using type = std::uint32_t;
};
template <>
struct UnsignedOf<double> {
  using type = std::uint64_t;
};

template <typename T, bool Swap>
inline T load(const unsigned char* p) {
  if constexpr (sizeof(T) == 1) {
    T v;
    std::memcpy(&v, p, 1);
    return v;
  } else {
    typename UnsignedOf<T>::type u;
    std::memcpy(&u, p, sizeof u);
    if constexpr (Swap) u = byte_swap(u);
    return std::bit_cast<T>(u);
  }
}

template <typename T>
inline T load(const unsigned char* p, bool swap) {
  return swap ? load<T, true>(p) : load<T, false>(p);
}

double load_double(const unsigned char* p, PlyType t, bool swap) {
  switch (t) {
    case PlyType::i8:
      return load<std::int8_t>(p, swap);
    case PlyType::u8:
      return load<std::uint8_t>(p, swap);
    case PlyType::i16:
      return load<std::int16_t>(p, swap);
    case PlyType::u16:
      return load<std::uint16_t>(p, swap);
    case PlyType::i32:
      return load<std::int32_t>(p, swap);
    case PlyType::u32:
      return load<std::uint32_t>(p, swap);
    case PlyType::f32:
      return static_cast<double>(load<float>(p, swap));
    case PlyType::f64:
      return load<double>(p, swap);
  }
  return 0.0;
}

// Integer types only (list counts and vertex indices; checked when the header is read).
std::int64_t load_integer(const unsigned char* p, PlyType t, bool swap) {
  switch (t) {
    case PlyType::i8:
      return load<std::int8_t>(p, swap);
    case PlyType::u8:
      return load<std::uint8_t>(p, swap);
    case PlyType::i16:
      return load<std::int16_t>(p, swap);
    case PlyType::u16:
      return load<std::uint16_t>(p, swap);
    case PlyType::i32:
      return load<std::int32_t>(p, swap);
    case PlyType::u32:
      return load<std::uint32_t>(p, swap);
    default:
      return 0;
  }
}

bool all_finite(const double* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

struct VertexPlan {
  int element = -1;
  int xyz[3] = {-1, -1, -1};
};

struct FacePlan {
  int element = -1;
  int list = -1;
};

class BodyReader {
 public:
  BodyReader(const MappedFile& file, const PlyHeader& header, const PlyBodyRequest& request)
      : file_(file),
        name_(file.name()),
        header_(header),
        request_(request),
        data_(file.bytes()),
        size_(file.size()),
        swap_((header.encoding == PlyEncoding::binary_le) !=
              (std::endian::native == std::endian::little)) {}

  PlyBodyResult run() {
    plan();
    if (header_.encoding == PlyEncoding::ascii) {
      run_ascii();
    } else {
      run_binary();
    }
    return std::move(result_);
  }

 private:
  void plan() {
    vertex_.element = header_.find("vertex");
    if (vertex_.element < 0) {
      fail_input(name_,
                 "the header has no 'element vertex' (expected a vertex element with x, y, z)");
    }
    const PlyElement& v = header_.elements[vertex_.element];
    static constexpr const char* kAxes[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      const int i = v.find(kAxes[a]);
      if (i < 0) {
        fail_input(name_,
                   "line {}: element vertex has no property '{}' (expected float or double "
                   "properties x, y and z)",
                   v.line, kAxes[a]);
      }
      if (v.properties[i].is_list) {
        fail_input(name_, "line {}: vertex property '{}' is a list (expected a float or double)",
                   v.properties[i].line, kAxes[a]);
      }
      vertex_.xyz[a] = i;
    }
    if (request_.faces == nullptr) return;
    face_.element = header_.find("face");
    if (face_.element < 0) {
      fail_input(name_,
                 "the header has no 'element face' (expected a mesh: a vertex element and a face "
                 "element with a vertex_indices list)");
    }
    const PlyElement& f = header_.elements[face_.element];
    face_.list = f.find("vertex_indices");
    if (face_.list < 0) face_.list = f.find("vertex_index");
    if (face_.list < 0) {
      fail_input(name_, "line {}: element face has no 'vertex_indices' (or 'vertex_index') list",
                 f.line);
    }
    const PlyProperty& p = f.properties[face_.list];
    if (!p.is_list || !ply_type_is_integer(p.type)) {
      fail_input(name_, "line {}: face property '{}' must be a list of integers", p.line, p.name);
    }
    if (v.count >= kNoIndex) {
      fail_input(name_, "line {}: {} vertices is more than a mesh can index (at most {})", v.line,
                 v.count, kNoIndex - 1);
    }
    vertex_count_ = v.count;
  }

  // ---- binary ----

  [[noreturn]] void truncated(const PlyElement& e, std::uint64_t row) const {
    if (size_ == header_.body_offset) {
      fail_input(name_,
                 "byte {}: file ends right after the header, which declares {} {} {} (truncated "
                 "body?)",
                 size_, e.count, e.name, e.count == 1 ? "element" : "elements");
    }
    fail_input(name_, "byte {}: file ends inside {} {} of {} (truncated body?)", size_, e.name,
               row + 1, e.count);
  }

  // Walks one row from pos and returns the position after it; offsets (if given) receive the
  // position of each property (of its count, for a list).
  std::size_t binary_row(const PlyElement& e, std::size_t pos, std::uint64_t row,
                         std::size_t* offsets) const {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      if (offsets != nullptr) offsets[i] = pos;
      if (!p.is_list) {
        const std::size_t s = ply_type_size(p.type);
        if (size_ - pos < s) truncated(e, row);
        pos += s;
        continue;
      }
      const std::size_t cs = ply_type_size(p.count_type);
      if (size_ - pos < cs) truncated(e, row);
      const std::int64_t n = load_integer(data_ + pos, p.count_type, swap_);
      if (n < 0) {
        fail_input(name_, "byte {}: {} {} of {}: negative list count {} for property '{}'", pos,
                   e.name, row + 1, e.count, n, p.name);
      }
      pos += cs;
      const std::uint64_t bytes = static_cast<std::uint64_t>(n) * ply_type_size(p.type);
      if (size_ - pos < bytes) truncated(e, row);
      pos += static_cast<std::size_t>(bytes);
    }
    return pos;
  }

  // Checks that `count` fixed-size rows fit from pos; returns the position after them.
  std::size_t fixed_rows_end(const PlyElement& e, std::size_t pos) const {
    const std::size_t stride = e.fixed_row_size();
    if (stride == 0) return pos;
    const std::uint64_t fit = (size_ - pos) / stride;
    if (fit < e.count) truncated(e, fit);
    return pos + static_cast<std::size_t>(e.count * stride);
  }

  // The first element after `ei` that declares rows, or the element count.
  std::size_t next_with_rows(std::size_t ei) const {
    std::size_t later = ei + 1;
    while (later < header_.elements.size() && header_.elements[later].count == 0) ++later;
    return later;
  }
  // After the last element read (`ei`): the elements after it are walked too, without keeping
  // anything, so that a file cut short anywhere in its declared body is reported (a mesh's faces
  // cut in the middle) and the bytes after the body are known. A file that ends right here while
  // the header declares more rows is said to end after this element.
  void check_rest(std::size_t ei, bool at_end) const {
    if (static_cast<int>(ei) < vertex_.element || static_cast<int>(ei) < face_.element) return;
    const std::size_t missing = next_with_rows(ei);
    if (!at_end || missing == header_.elements.size()) return;
    const PlyElement& e = header_.elements[ei];
    const PlyElement& m = header_.elements[missing];
    fail_input(name_,
               "file ends after the {}, but the header declares {} {} after them (line {}; "
               "truncated file?)",
               e.name == "vertex" ? "vertices" : e.name, m.count, m.name, m.line);
  }

  void run_binary() {
    std::size_t pos = header_.body_offset;
    for (std::size_t ei = 0; ei < header_.elements.size(); ++ei) {
      const PlyElement& e = header_.elements[ei];
      if (static_cast<int>(ei) == vertex_.element) {
        pos = binary_vertices(e, pos);
      } else if (static_cast<int>(ei) == face_.element) {
        pos = binary_faces(e, pos);
      } else if (!e.has_lists()) {
        pos = fixed_rows_end(e, pos);
      } else {
        for (std::uint64_t r = 0; r < e.count; ++r) {
          pos = binary_row(e, pos, r, nullptr);
          if (r % kSkipRunRows == kSkipRunRows - 1) release_skipped(pos);
        }
      }
      check_rest(ei, pos == size_);
    }
    result_.end = pos;
  }

  template <typename T, bool Swap>
  std::size_t convert_fixed(const unsigned char* base, std::size_t stride, std::uint64_t count,
                            const std::size_t off[3], double* out) {
    const bool drop = request_.drop_non_finite;
    std::size_t kept = 0;
    std::uint64_t bad = 0;
    for (std::uint64_t r = 0; r < count; ++r) {
      const unsigned char* row = base + r * stride;
      double* o = out + 3 * kept;
      o[0] = static_cast<double>(load<T, Swap>(row + off[0]));
      o[1] = static_cast<double>(load<T, Swap>(row + off[1]));
      o[2] = static_cast<double>(load<T, Swap>(row + off[2]));
      if (drop && !all_finite(o)) {
        ++bad;
      } else {
        ++kept;
      }
    }
    result_.non_finite += bad;
    return kept;
  }

  // Converts `count` fixed-size rows into out; returns the points kept.
  std::size_t convert_rows(const unsigned char* base, std::size_t stride, std::uint64_t count,
                           const std::size_t off[3], const PlyType type[3], double* out) {
    const bool same = type[0] == type[1] && type[1] == type[2];
    if (same && type[0] == PlyType::f32) {
      return swap_ ? convert_fixed<float, true>(base, stride, count, off, out)
                   : convert_fixed<float, false>(base, stride, count, off, out);
    }
    if (same && type[0] == PlyType::f64) {
      return swap_ ? convert_fixed<double, true>(base, stride, count, off, out)
                   : convert_fixed<double, false>(base, stride, count, off, out);
    }
    std::size_t kept = 0;
    for (std::uint64_t r = 0; r < count; ++r) {
      const unsigned char* row = base + r * stride;
      double* o = out + 3 * kept;
      for (int a = 0; a < 3; ++a) o[a] = load_double(row + off[a], type[a], swap_);
      if (request_.drop_non_finite && !all_finite(o)) {
        ++result_.non_finite;
      } else {
        ++kept;
      }
    }
    return kept;
  }

  // Rows of an element walked but not kept (a mesh's faces when only its points are read):
  // streaming, the pages before them are released every this many, so that walking them does
  // not hold the file in the resident set (a 260 MB face list took it from 31 to 283 MB).
  static constexpr std::uint64_t kSkipRunRows = std::uint64_t{1} << 16;
  void release_skipped(std::size_t consumed) const {
    if (request_.points != nullptr) file_.release_before(consumed);
  }

  // Streaming: hands the points collected so far to the sink and releases the file's pages
  // before `consumed`. Collecting: nothing to do.
  void emit(std::size_t consumed) {
    if (request_.points == nullptr) return;
    result_.streamed += result_.xyz.size() / 3;
    if (!result_.xyz.empty()) (*request_.points)(result_.xyz);
    result_.xyz.clear();
    file_.release_before(consumed);
  }

  std::size_t binary_vertices(const PlyElement& e, std::size_t pos) {
    std::vector<double>& xyz = result_.xyz;
    const bool drop = request_.drop_non_finite;
    const bool streaming = request_.points != nullptr;
    if (!e.has_lists()) {
      const std::size_t end = fixed_rows_end(e, pos);
      std::size_t off[3] = {0, 0, 0};
      PlyType type[3] = {};
      for (int a = 0; a < 3; ++a) {
        for (int i = 0; i < vertex_.xyz[a]; ++i) off[a] += ply_type_size(e.properties[i].type);
        type[a] = e.properties[vertex_.xyz[a]].type;
      }
      const std::size_t stride = e.fixed_row_size();
      // Collecting converts the element in one run; streaming in runs of kScanChunkPoints.
      const std::uint64_t run = streaming ? kScanChunkPoints : std::max<std::uint64_t>(e.count, 1);
      for (std::uint64_t first = 0; first < e.count; first += run) {
        const std::uint64_t rows = std::min(run, e.count - first);
        xyz.resize(static_cast<std::size_t>(rows) * 3);
        const std::size_t kept =
            convert_rows(data_ + pos + first * stride, stride, rows, off, type, xyz.data());
        xyz.resize(kept * 3);
        emit(pos + static_cast<std::size_t>((first + rows) * stride));
      }
      return end;
    }
    std::vector<std::size_t> offsets(e.properties.size());
    std::uint64_t reserve = std::min<std::uint64_t>(e.count, (size_ - pos) / 3);
    if (streaming) reserve = std::min<std::uint64_t>(reserve, kScanChunkPoints);
    xyz.reserve(static_cast<std::size_t>(reserve) * 3);
    for (std::uint64_t r = 0; r < e.count; ++r) {
      pos = binary_row(e, pos, r, offsets.data());
      double o[3];
      for (int a = 0; a < 3; ++a) {
        const PlyProperty& p = e.properties[vertex_.xyz[a]];
        o[a] = load_double(data_ + offsets[vertex_.xyz[a]], p.type, swap_);
      }
      if (drop && !all_finite(o)) {
        ++result_.non_finite;
        continue;
      }
      xyz.insert(xyz.end(), o, o + 3);
      if (streaming && xyz.size() == 3 * kScanChunkPoints) emit(pos);
    }
    emit(pos);
    return pos;
  }

  void add_polygon(const std::int64_t* idx, std::size_t n) {
    if (n < 3) return;  // points and edges are no triangles
    std::vector<Triangle>& out = *request_.faces;
    for (std::size_t k = 1; k + 1 < n; ++k) {
      out.push_back(
          {static_cast<Index>(idx[0]), static_cast<Index>(idx[k]), static_cast<Index>(idx[k + 1])});
    }
  }

  std::size_t binary_faces(const PlyElement& e, std::size_t pos) {
    std::vector<std::size_t> offsets(e.properties.size());
    const PlyProperty& list = e.properties[face_.list];
    const std::size_t cs = ply_type_size(list.count_type);
    const std::size_t is = ply_type_size(list.type);
    const std::uint64_t fit = (size_ - pos) / (cs + 3 * is);  // rows of triangles that fit
    request_.faces->reserve(request_.faces->size() +
                            static_cast<std::size_t>(std::min<std::uint64_t>(e.count, fit)));
    std::vector<std::int64_t> idx;
    for (std::uint64_t r = 0; r < e.count; ++r) {
      pos = binary_row(e, pos, r, offsets.data());
      const std::size_t at = offsets[face_.list];
      const auto n = static_cast<std::size_t>(load_integer(data_ + at, list.count_type, swap_));
      idx.resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t item = at + cs + k * is;
        idx[k] = load_integer(data_ + item, list.type, swap_);
        if (idx[k] < 0 || static_cast<std::uint64_t>(idx[k]) >= vertex_count_) {
          fail_input(name_,
                     "byte {}: {} {} of {}: vertex index {} out of range (the vertex element has "
                     "{} vertices)",
                     item, e.name, r + 1, e.count, idx[k], vertex_count_);
        }
      }
      add_polygon(idx.data(), n);
    }
    return pos;
  }

  // ---- ascii ----

  [[noreturn]] void ascii_truncated(const LineCursor& lines, const PlyElement& e,
                                    std::uint64_t row) const {
    fail_input(name_, "line {}: file ends before {} {} of {} (truncated body?)", lines.line(),
               e.name, row + 1, e.count);
  }

  // Token index of every property in a row (of its count for a list); throws unless the row
  // has exactly the tokens its properties and list counts call for.
  void ascii_layout(const PlyElement& e, const std::vector<std::string_view>& tokens,
                    std::uint64_t line, std::uint64_t row, std::size_t* where) const {
    std::size_t t = 0;
    bool short_row = false;
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      where[i] = t;
      if (!p.is_list || t >= tokens.size()) {
        short_row = short_row || (p.is_list && t >= tokens.size());
        ++t;
        continue;
      }
      std::int64_t n = -1;
      if (!parse_integer(tokens[t], n) || n < 0) {
        fail_input(name_,
                   "line {}: {} {} of {}: expected a list count (a non-negative integer) for "
                   "property '{}', found {}",
                   line, e.name, row + 1, e.count, p.name, quote_token(tokens[t]));
      }
      t += 1 + static_cast<std::size_t>(n);
    }
    if (t != tokens.size()) {
      fail_input(name_, "line {}: {} {} of {}: expected {}{} values, found {}", line, e.name,
                 row + 1, e.count, short_row ? "at least " : "", t, tokens.size());
    }
  }

  void ascii_vertices(LineCursor& lines, const PlyElement& e) {
    std::vector<double>& xyz = result_.xyz;
    const bool drop = request_.drop_non_finite;
    const bool streaming = request_.points != nullptr;
    std::uint64_t reserve = std::min<std::uint64_t>(e.count, size_ / 6);
    if (streaming) reserve = std::min<std::uint64_t>(reserve, kScanChunkPoints);
    xyz.reserve(static_cast<std::size_t>(reserve) * 3);
    std::vector<std::string_view> tokens;
    std::vector<std::size_t> where(e.properties.size());
    for (std::size_t i = 0; i < where.size(); ++i) where[i] = i;
    const bool lists = e.has_lists();
    std::string_view line;
    for (std::uint64_t r = 0; r < e.count; ++r) {
      if (!lines.next_nonblank(line)) ascii_truncated(lines, e, r);
      split_blanks(line, tokens);
      if (lists) {
        ascii_layout(e, tokens, lines.line(), r, where.data());
      } else if (tokens.size() != e.properties.size()) {
        fail_input(name_, "line {}: {} {} of {}: expected {} values, found {}", lines.line(),
                   e.name, r + 1, e.count, e.properties.size(), tokens.size());
      }
      double o[3];
      for (int a = 0; a < 3; ++a) {
        const std::string_view tok = tokens[where[vertex_.xyz[a]]];
        if (!parse_number(tok, o[a])) {
          fail_input(name_, "line {}: {} {} of {}: expected a number for property '{}', found {}",
                     lines.line(), e.name, r + 1, e.count, e.properties[vertex_.xyz[a]].name,
                     quote_bad_number(tok));
        }
      }
      if (drop && !all_finite(o)) {
        ++result_.non_finite;
        continue;
      }
      xyz.insert(xyz.end(), o, o + 3);
      if (streaming && xyz.size() == 3 * kScanChunkPoints) emit(lines.position());
    }
    emit(lines.position());
  }

  void ascii_faces(LineCursor& lines, const PlyElement& e) {
    std::vector<std::string_view> tokens;
    std::vector<std::size_t> where(e.properties.size());
    std::vector<std::int64_t> idx;
    std::string_view line;
    for (std::uint64_t r = 0; r < e.count; ++r) {
      if (!lines.next_nonblank(line)) ascii_truncated(lines, e, r);
      split_blanks(line, tokens);
      ascii_layout(e, tokens, lines.line(), r, where.data());
      const std::size_t at = where[face_.list];
      std::int64_t n = 0;
      parse_integer(tokens[at], n);  // checked by ascii_layout
      idx.resize(static_cast<std::size_t>(n));
      for (std::size_t k = 0; k < idx.size(); ++k) {
        const std::string_view tok = tokens[at + 1 + k];
        if (!parse_integer(tok, idx[k])) {
          fail_input(name_, "line {}: {} {} of {}: expected an integer vertex index, found {}",
                     lines.line(), e.name, r + 1, e.count, quote_token(tok));
        }
        if (idx[k] < 0 || static_cast<std::uint64_t>(idx[k]) >= vertex_count_) {
          fail_input(name_,
                     "line {}: {} {} of {}: vertex index {} out of range (the vertex element has "
                     "{} vertices)",
                     lines.line(), e.name, r + 1, e.count, idx[k], vertex_count_);
        }
      }
      add_polygon(idx.data(), idx.size());
    }
  }

  void run_ascii() {
    LineCursor lines(file_.view(), header_.body_offset, header_.lines);
    std::string_view line;
    for (std::size_t ei = 0; ei < header_.elements.size(); ++ei) {
      const PlyElement& e = header_.elements[ei];
      if (static_cast<int>(ei) == vertex_.element) {
        ascii_vertices(lines, e);
      } else if (static_cast<int>(ei) == face_.element) {
        ascii_faces(lines, e);
      } else {
        for (std::uint64_t r = 0; r < e.count; ++r) {
          if (!lines.next_nonblank(line)) ascii_truncated(lines, e, r);
          if (r % kSkipRunRows == kSkipRunRows - 1) release_skipped(lines.position());
        }
      }
      check_rest(ei, !lines.has_nonblank());
    }
    result_.end = lines.position();
  }

  const MappedFile& file_;
  const std::string& name_;
  const PlyHeader& header_;
  const PlyBodyRequest& request_;
  const unsigned char* data_;
  std::size_t size_;
  bool swap_;
  VertexPlan vertex_;
  FacePlan face_;
  std::uint64_t vertex_count_ = 0;
  PlyBodyResult result_;
};

}  // namespace

PlyBodyResult read_ply_body(const MappedFile& file, const PlyHeader& header,
                            const PlyBodyRequest& request) {
  return BodyReader(file, header, request).run();
}

}  // namespace g2s::io
