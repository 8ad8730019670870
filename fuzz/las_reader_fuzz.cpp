// libFuzzer target: the LAS point reader behind read_points (header checks, VLR walk for the
// LASzip marker, counts, record stride, scale and offset), collected and streamed. Inputs without
// the "LASF" signature are left to the other readers' targets.
#include <vector>

#include "fuzz_input.hpp"
#include "io/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const g2s::io::MappedFile file = g2s::fuzz::as_file(data, size);
  if (!g2s::io::has_las_signature(file)) return 0;
  g2s::fuzz::expect_clean_refusal([&] {
    g2s::ReadReport report;
    g2s::io::read_points_from(file, report);
  });
  return g2s::fuzz::expect_clean_refusal([&] {
    g2s::ReadReport report;
    // The sink takes each run's vector, as the read-ahead does: the reader refills another.
    const g2s::io::RunSink sink = [](std::vector<double>& xyz) { std::vector<double>{}.swap(xyz); };
    g2s::io::read_las_points(file, report, &sink);
  });
}
