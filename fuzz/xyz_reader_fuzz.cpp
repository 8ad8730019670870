// libFuzzer target: the text point reader (XYZ, PTS, CSV: separators, comments, count and
// column-name lines, numbers). Called directly, past read_points's refusal of binary bytes, so
// that every byte value reaches the parser.
#include "fuzz_input.hpp"
#include "io/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const g2s::io::MappedFile file = g2s::fuzz::as_file(data, size);
  return g2s::fuzz::expect_clean_refusal([&] {
    g2s::ReadReport report;
    g2s::io::read_xyz_points(file, report, nullptr);
  });
}
