// libFuzzer target: what `g2s stats` does with a mesh file: read_mesh (binary STL, ASCII STL,
// PLY with faces) and then compute_stats on whatever was read.
#include "fuzz_input.hpp"
#include "g2s/stats.hpp"
#include "io/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const g2s::io::MappedFile file = g2s::fuzz::as_file(data, size);
  return g2s::fuzz::expect_clean_refusal(
      [&] { g2s::compute_stats(g2s::io::read_mesh_from(file)); });
}
