// The g2s subcommands. Each add_*_command registers one on the app with a callback that does
// the work; failures throw g2s::Error, which main() turns into the documented exit code.
#pragma once

#include <CLI/CLI.hpp>

#include "g2s/pipeline.hpp"
#include "mesh_output.hpp"

namespace g2s::cli {

void add_mesh_command(CLI::App& app);
void add_stage_commands(CLI::App& app);  // grow, stitch
void add_stats_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_tile_commands(CLI::App& app);  // tile and tile-info
void add_render_command(CLI::App& app);

// Options shared by the commands that mesh: G2S parameters, and where and how to write.
void add_mesh_options(CLI::App& cmd, PipelineOptions& options);
void add_output_options(CLI::App& cmd, OutputArgs& out);

// Sets how much free memory the allocator may keep for reuse (a 64th of a budget of bytes, at
// most 32 MiB): g2s mesh calls it with its --memory budget (tools/main.cpp).
void fit_heap_to_budget(std::uint64_t budget_bytes);
void one_heap_for_all_threads();

}  // namespace g2s::cli
