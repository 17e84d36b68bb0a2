#pragma once
// The mcfbench subcommands; each registers its options on the CLI11 app and returns the
// callback's exit status through run(). A command only parses its flags and calls one function
// of a lower layer (harness/, datasets/), which holds the logic and is tested there.

#include <CLI/CLI.hpp>

#include <functional>

namespace mcf {

/// Adds a subcommand; `run` is set to the function that executes it after parsing.
void add_flow_command(CLI::App& app, std::function<int()>& run);
void add_mesh_info_command(CLI::App& app, std::function<int()>& run);
void add_run_command(CLI::App& app, std::function<int()>& run);
void add_submit_command(CLI::App& app, std::function<int()>& run);
void add_expand_command(CLI::App& app, std::function<int()>& run);
void add_collect_command(CLI::App& app, std::function<int()>& run);
void add_compare_command(CLI::App& app, std::function<int()>& run);
void add_distance_command(CLI::App& app, std::function<int()>& run);
void add_history_command(CLI::App& app, std::function<int()>& run);

}  // namespace mcf
