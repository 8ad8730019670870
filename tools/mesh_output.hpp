// Shared by `g2s mesh` and `g2s stitch`: stream the pipeline's mesh to the output and print the
// summary line (or the JSON object) with the mesh's defects.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "g2s/pipeline.hpp"
#include "progress.hpp"

namespace g2s::cli {

struct OutputArgs {
  std::string output;
  bool ascii = false;
  bool quiet = false;
  bool json = false;
  bool no_stats = false;
  // Bytes reading the written mesh back may take, when its defects could not be counted as it
  // streamed out (it is read back whole); 0: no limit.
  std::uint64_t memory = 0;
};

// What the summary names besides the mesh itself.
struct RunFacts {
  std::string input;                // the cloud or store meshed
  std::uint64_t non_finite = 0;     // points the reader dropped
  std::uint64_t ignored_bytes = 0;  // after a PLY's declared vertices
  std::chrono::steady_clock::time_point start;
  // Called once the mesh is complete at its target, before it is measured (the temporary tile
  // store can go then); may be empty.
  std::function<void()> output_written;
  // The temporary tile store, removed by an interrupt after the mesh is complete; may be empty.
  std::string temporary_store;
  StageTime tile;  // cutting the cloud into the tile store (zero when a kept store was reused)
};

// Runs the pipeline (`run` feeds the sink it is given) into args.output, written atomically,
// then reports. With no triangle nothing is written: Error(no_surface) says why, from the
// points of `source`.
void write_and_report(const TileSource& source,
                      const std::function<PipelineSummary(MeshSink&)>& run, const OutputArgs& args,
                      const RunFacts& facts);

}  // namespace g2s::cli
