// libFuzzer target: the PLY point reader behind read_points (header parser; ascii, binary little
// and big endian bodies; lists, skipped elements, non-finite points). Inputs without the "ply"
// magic line are left to xyz_reader_fuzz.
#include "fuzz_input.hpp"
#include "io/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const g2s::io::MappedFile file = g2s::fuzz::as_file(data, size);
  if (!g2s::io::has_ply_magic(file)) return 0;
  return g2s::fuzz::expect_clean_refusal([&] {
    g2s::ReadReport report;
    g2s::io::read_points_from(file, report);
  });
}
