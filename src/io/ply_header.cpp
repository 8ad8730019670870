// PLY header parser: "ply", format, element, property (scalar or list, every PLY type name),
// comment/obj_info, end_header; CRLF and trailing blanks tolerated. Errors name the header
// line and say what was expected, so a hand-edited or foreign header is easy to fix.
#include <array>
#include <string_view>
#include <vector>

#include "io/ply_format.hpp"
#include "io/text_util.hpp"

namespace g2s::io {
namespace {

struct TypeName {
  std::string_view name;
  PlyType type;
};

constexpr std::array<TypeName, 16> kTypeNames{{
    {"char", PlyType::i8},
    {"uchar", PlyType::u8},
    {"short", PlyType::i16},
    {"ushort", PlyType::u16},
    {"int", PlyType::i32},
    {"uint", PlyType::u32},
    {"float", PlyType::f32},
    {"double", PlyType::f64},
    {"int8", PlyType::i8},
    {"uint8", PlyType::u8},
    {"int16", PlyType::i16},
    {"uint16", PlyType::u16},
    {"int32", PlyType::i32},
    {"uint32", PlyType::u32},
    {"float32", PlyType::f32},
    {"float64", PlyType::f64},
}};

bool type_from_name(std::string_view name, PlyType& type) {
  for (const auto& t : kTypeNames) {
    if (t.name == name) {
      type = t.type;
      return true;
    }
  }
  return false;
}

constexpr const char* kTypeList =
    "char, uchar, short, ushort, int, uint, float, double or int8, uint8, int16, uint16, int32, "
    "uint32, float32, float64";

}  // namespace

bool PlyElement::has_lists() const {
  for (const auto& p : properties) {
    if (p.is_list) return true;
  }
  return false;
}

std::size_t PlyElement::fixed_row_size() const {
  std::size_t size = 0;
  for (const auto& p : properties) size += ply_type_size(p.type);
  return size;
}

int PlyElement::find(std::string_view property) const {
  for (std::size_t i = 0; i < properties.size(); ++i) {
    if (properties[i].name == property) return static_cast<int>(i);
  }
  return -1;
}

int PlyHeader::find(std::string_view element) const {
  for (std::size_t i = 0; i < elements.size(); ++i) {
    if (elements[i].name == element) return static_cast<int>(i);
  }
  return -1;
}

const char* ply_format_name(PlyEncoding encoding) {
  switch (encoding) {
    case PlyEncoding::ascii:
      return "ply-ascii";
    case PlyEncoding::binary_le:
      return "ply-binary-le";
    case PlyEncoding::binary_be:
      return "ply-binary-be";
  }
  return "ply";
}

PlyHeader parse_ply_header(const MappedFile& file) {
  const std::string& name = file.name();
  PlyHeader header;
  LineCursor lines(file.view(), 0, 0);
  std::string_view line;
  std::vector<std::string_view> tokens;
  bool have_format = false;
  bool first = true;
  while (lines.next(line)) {
    const std::uint64_t n = lines.line();
    if (first) {
      first = false;
      split_blanks(line, tokens);
      if (tokens.size() != 1 || tokens[0] != "ply") {
        fail_input(name, "line 1: expected the PLY magic line 'ply', found {}", quote_token(line));
      }
      continue;
    }
    split_blanks(line, tokens);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (have_format) fail_input(name, "line {}: second 'format' line", n);
      if (tokens.size() < 2 || tokens.size() > 3) {
        fail_input(
            name, "line {}: expected 'format ascii|binary_little_endian|binary_big_endian 1.0'", n);
      }
      if (tokens[1] == "ascii") {
        header.encoding = PlyEncoding::ascii;
      } else if (tokens[1] == "binary_little_endian") {
        header.encoding = PlyEncoding::binary_le;
      } else if (tokens[1] == "binary_big_endian") {
        header.encoding = PlyEncoding::binary_be;
      } else {
        fail_input(name,
                   "line {}: unknown PLY format {} (expected ascii, binary_little_endian or "
                   "binary_big_endian)",
                   n, quote_token(tokens[1]));
      }
      have_format = true;
    } else if (key == "element") {
      std::uint64_t count = 0;
      if (tokens.size() != 3 || !parse_number(tokens[2], count)) {
        fail_input(name, "line {}: expected 'element NAME COUNT' with a non-negative COUNT", n);
      }
      for (const PlyElement& before : header.elements) {
        if (before.name == tokens[1]) {
          fail_input(name, "line {}: a second element '{}' (the first is on line {})", n,
                     before.name, before.line);
        }
      }
      PlyElement element;
      element.name = std::string(tokens[1]);
      element.count = count;
      element.line = n;
      header.elements.push_back(std::move(element));
    } else if (key == "property") {
      if (header.elements.empty()) {
        fail_input(name, "line {}: 'property' before any 'element' line", n);
      }
      PlyProperty property;
      property.line = n;
      if (tokens.size() >= 2 && tokens[1] == "list") {
        if (tokens.size() != 5) {
          fail_input(name, "line {}: expected 'property list COUNT_TYPE ITEM_TYPE NAME'", n);
        }
        if (!type_from_name(tokens[2], property.count_type)) {
          fail_input(name, "line {}: unknown list count type {} (expected {})", n,
                     quote_token(tokens[2]), kTypeList);
        }
        if (!ply_type_is_integer(property.count_type)) {
          fail_input(name, "line {}: list count type {} is not an integer type", n,
                     quote_token(tokens[2]));
        }
        if (!type_from_name(tokens[3], property.type)) {
          fail_input(name, "line {}: unknown property type {} (expected {})", n,
                     quote_token(tokens[3]), kTypeList);
        }
        property.is_list = true;
        property.name = std::string(tokens[4]);
      } else {
        if (tokens.size() != 3) fail_input(name, "line {}: expected 'property TYPE NAME'", n);
        if (!type_from_name(tokens[1], property.type)) {
          fail_input(name, "line {}: unknown property type {} (expected {})", n,
                     quote_token(tokens[1]), kTypeList);
        }
        property.name = std::string(tokens[2]);
      }
      // Two x (or y, or z) properties: which one is the coordinate would be a guess. Other
      // repeated names are left alone (g2s reads no other property).
      if (property.name == "x" || property.name == "y" || property.name == "z") {
        for (const PlyProperty& before : header.elements.back().properties) {
          if (before.name != property.name) continue;
          fail_input(name,
                     "line {}: a second property '{}' in element '{}' (the first is on line {})", n,
                     before.name, header.elements.back().name, before.line);
        }
      }
      header.elements.back().properties.push_back(std::move(property));
    } else if (key == "end_header") {
      if (tokens.size() != 1) fail_input(name, "line {}: unexpected text after 'end_header'", n);
      if (!have_format) fail_input(name, "line {}: the header has no 'format' line", n);
      header.body_offset = lines.position();
      header.lines = n;
      return header;
    } else {
      fail_input(name,
                 "line {}: unknown header keyword {} (expected format, element, property, "
                 "comment, obj_info or end_header)",
                 n, quote_token(key));
    }
  }
  fail_input(name, "line {}: file ends inside the PLY header (no 'end_header' line; truncated?)",
             lines.line());
}

}  // namespace g2s::io
