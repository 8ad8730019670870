// Shared by `g2s mesh` and `g2s stitch`: write the finished mesh and print the summary line (or
// the JSON object) with the mesh's defects.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "g2s/pipeline.hpp"

namespace g2s::cli {

struct OutputArgs {
  std::string output;
  bool ascii = false;
  bool quiet = false;
  bool json = false;
  bool no_stats = false;
};

// What the summary names besides the mesh itself.
struct RunFacts {
  std::string input;             // the cloud or store meshed
  std::uint64_t non_finite = 0;     // points the reader dropped
  std::uint64_t ignored_bytes = 0;  // after a PLY's declared vertices
  std::chrono::steady_clock::time_point start;
};

// Writes `mesh` to args.output (atomically; Error(bad_input) if it has no triangle) and reports.
void write_and_report(PipelineMesh& mesh, const OutputArgs& args, const RunFacts& facts);

}  // namespace g2s::cli
