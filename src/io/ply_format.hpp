// The PLY header model shared by the point and mesh readers: elements, scalar and list
// properties with their types, and the body encoding; plus parse_ply_header (ply_header.cpp)
// and read_ply_body (ply_reader.cpp), which walks every element and extracts x, y, z and faces.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "g2s/types.hpp"
#include "io/mapped_file.hpp"
#include "io/readers.hpp"

namespace g2s::io {

enum class PlyType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };
enum class PlyEncoding { ascii, binary_le, binary_be };

inline std::size_t ply_type_size(PlyType t) {
  switch (t) {
    case PlyType::i8:
    case PlyType::u8:
      return 1;
    case PlyType::i16:
    case PlyType::u16:
      return 2;
    case PlyType::i32:
    case PlyType::u32:
    case PlyType::f32:
      return 4;
    case PlyType::f64:
      return 8;
  }
  return 0;
}

inline bool ply_type_is_integer(PlyType t) {
  return t != PlyType::f32 && t != PlyType::f64;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::f32;  // the item type for lists
  bool is_list = false;
  PlyType count_type = PlyType::u8;  // lists only
  std::uint64_t line = 0;            // header line, for messages
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  std::uint64_t line = 0;

  bool has_lists() const;
  std::size_t fixed_row_size() const;         // binary row size when there are no lists
  int find(std::string_view property) const;  // index or -1
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;               // first byte after the end_header line
  std::uint64_t lines = 0;                   // header lines, end_header included
  int find(std::string_view element) const;  // index or -1
};

// Parses the header at the start of `file` (which starts with "ply"). Throws Error(bad_input)
// with the header line number for anything malformed.
PlyHeader parse_ply_header(const MappedFile& file);

// "ply-ascii", "ply-binary-le", "ply-binary-be".
const char* ply_format_name(PlyEncoding encoding);

// What read_ply_body should extract.
struct PlyBodyRequest {
  bool drop_non_finite = true;             // points: drop and count NaN/Inf vertices
  std::vector<Triangle>* faces = nullptr;  // meshes: the face element, fanned into triangles
  // Streaming: the vertices go to this sink, at most kScanChunkPoints at a time, instead of
  // into the result, and the pages read are released as the body is consumed.
  const RunSink* points = nullptr;
};

struct PlyBodyResult {
  std::vector<double> xyz;  // empty when streamed to a sink
  std::uint64_t non_finite = 0;
  std::uint64_t streamed = 0;  // points handed to the sink
  std::size_t end = 0;         // first byte after the last element read
};

// Walks the body of every element in header order (other elements and properties skipped,
// trailing bytes after the last element ignored). Needs a "vertex" element with x, y, z; and a
// "face" element with a vertex_indices (or vertex_index) list when faces are asked for.
PlyBodyResult read_ply_body(const MappedFile& file, const PlyHeader& header,
                            const PlyBodyRequest& request);

}  // namespace g2s::io
