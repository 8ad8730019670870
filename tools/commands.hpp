// The g2s subcommands. Each add_*_command registers one on the app with a callback that does
// the work; failures throw g2s::Error, which main() turns into the documented exit code.
#pragma once

#include <CLI/CLI.hpp>

namespace g2s::cli {

void add_mesh_command(CLI::App& app);
void add_stats_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_render_command(CLI::App& app);

}  // namespace g2s::cli
