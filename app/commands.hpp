// The scanbench subcommands. Each add_* registers one subcommand on the CLI11
// app; its callback does the work and throws on failure (main maps exception
// types to exit codes: see exit_codes below).
#pragma once

#include <CLI/CLI.hpp>

namespace scanbench::app {

// Exit codes of every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;   // the work failed for reasons other than the input
inline constexpr int kExitBadInput = 2;  // bad file, bad argument, usage error

void add_import_command(CLI::App& app);
void add_info_command(CLI::App& app);
void add_export_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_geometry_command(CLI::App& app);
void add_register_command(CLI::App& app);
void add_merge_command(CLI::App& app);
// history, undo and redo.
void add_history_commands(CLI::App& app);
void add_check_command(CLI::App& app);
void add_objects_command(CLI::App& app);
void add_segment_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_recolor_command(CLI::App& app);
void add_harmonize_command(CLI::App& app);
void add_workbench_command(CLI::App& app);

}  // namespace scanbench::app
