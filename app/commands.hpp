// The scanbench subcommands. Each add_* registers one subcommand on the CLI11
// app; its callback does the work and throws on failure (main maps exception
// types to exit codes: see exit_codes below).
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <map>
#include <string>

#include "acquisition/formats/json_input.hpp"
#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "modeling/command_json.hpp"

namespace scanbench::store {
class Project;
}

namespace scanbench::app {

// Exit codes of every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;   // the work failed for reasons other than the input
inline constexpr int kExitBadInput = 2;  // bad file, bad argument, usage error

void add_import_command(CLI::App& app);
void add_info_command(CLI::App& app);
void add_export_command(CLI::App& app);
// The bench suites' own command (bench/command_bench.cpp), in the
// scanbench-bench executable only: scanbench hands `bench` calls to it.
void add_bench_command(CLI::App& app);
inline constexpr const char* kBenchDescription =
    "Measure a stage: accuracy against ground truth and speed against PCL, one run.";
void add_simulate_command(CLI::App& app);
void add_geometry_command(CLI::App& app);
void add_lod_command(CLI::App& app);
// The project's level-of-detail store (docs/lod.md), built first, with a
// progress bar, when it is missing or no longer current; `built_seconds`
// is how long that took (0 when it was current).
std::filesystem::path current_lod_store(const store::Project& project, double& built_seconds);
void add_register_command(CLI::App& app);
void add_merge_command(CLI::App& app);
// history, undo and redo.
void add_history_commands(CLI::App& app);
void add_check_command(CLI::App& app);
void add_objects_command(CLI::App& app);
void add_measurements_command(CLI::App& app);
void add_segment_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_recolor_command(CLI::App& app);
void add_harmonize_command(CLI::App& app);
void add_workbench_command(CLI::App& app);

// The --threads option of every parallel command, validated once: 0 (all
// cores) to core::kMaxThreads, anything else a usage error; a count above
// the machine's cores runs as many workers as it has (core::worker_count).
inline void add_threads_option(CLI::App* command, int& threads) {
  command
      ->add_option("--threads", threads,
                   "Worker threads: 0 = all cores (the default), at most " +
                       std::to_string(core::kMaxThreads) + "; more than the cores run as many")
      ->check(CLI::Range(0, core::kMaxThreads));
}

// The --memory-limit option of every streamed stage: how much memory the
// scans it holds at once may take, with a unit ("6GB", "512MB"; kB = 1000
// bytes, KiB = 1024); 0 or absent: three quarters of the memory available
// (modeling::memory_limit_or_default).
inline void add_memory_limit_option(CLI::App* command, std::uint64_t& bytes) {
  command
      ->add_option("--memory-limit", bytes,
                   "Memory for the scans held at once, e.g. 6GB (default: 3/4 of what is "
                   "available); a stage that needs more says so and changes nothing")
      ->transform(CLI::AsSizeValue(true));
}

// The limit add_memory_limit_option read: none (the default) for 0.
inline std::optional<std::uint64_t> memory_limit_of(std::uint64_t bytes) {
  return bytes > 0 ? std::optional(bytes) : std::nullopt;
}

// A choice among named values of `Enum`, any case: the option's text
// becomes the value's number for CLI11 to read, and a text that names none
// is a usage error that lists the names ("--format: xyz is not one of csv,
// e57, ..."; CLI11's own CheckedTransformer shows the numbers too).
template <typename Enum>
CLI::Validator one_of(const std::map<std::string, Enum>& names) {
  std::string list;
  for (const auto& entry : names) list += (list.empty() ? "" : ", ") + entry.first;
  return CLI::Validator(
      [names, list](std::string& text) -> std::string {
        for (const auto& [name, value] : names) {
          if (CLI::detail::to_lower(text) == CLI::detail::to_lower(name)) {
            text = std::to_string(static_cast<long long>(value));
            return {};
          }
        }
        return text + " is not one of " + list;
      },
      "", "one_of");
}

// The --settings option of the batch commands (geometry, register, merge,
// harmonize): run with the settings of an earlier command, as `scanbench
// history PROJECT --settings ID` prints them. The options that change
// settings are then refused: they are in the file.
inline CLI::Option* add_settings_option(CLI::App* command, std::string& file) {
  return command
      ->add_option("--settings", file,
                   "Run with these settings (JSON, as `scanbench history PROJECT --settings ID` "
                   "prints a command's); missing keys take the defaults")
      ->check(CLI::ExistingFile);
}

// Reads a --settings file. Throws core::InputError naming the file and the
// key when it is not JSON, has a key the settings do not, a value of the
// wrong type or outside its range (modeling::SettingsSource::kUser).
template <typename Settings>
Settings read_settings_file(const std::string& file) {
  constexpr std::uintmax_t kMaxBytes = 1 << 20;
  return modeling::settings_from_json<Settings>(acquisition::read_json_file(file, kMaxBytes), file,
                                                modeling::SettingsSource::kUser);
}

// Runs `work`, a command of modeling/, and names `project` in a refusal that
// names no file: the commands name the node or scan at fault, the CLI the
// project it is in.
template <typename Work>
auto naming_project(const std::filesystem::path& project, Work&& work) {
  try {
    return work();
  } catch (const core::InputError& error) {
    if (!error.file().empty()) throw;
    throw core::InputError(project.string(), error.position(), error.problem());
  }
}

}  // namespace scanbench::app
