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

}  // namespace g2s::cli
