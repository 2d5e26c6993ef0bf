// scanbench merge PROJECT [--settings FILE] [--threads N] [--memory-limit SIZE] [--json]
#include <fmt/core.h>

#include <memory>
#include <string>

#include "app/commands.hpp"
#include "app/progress_bar.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"

namespace scanbench::app {
namespace {

struct MergeOptions {
  std::string project;
  registration::MergeSettings settings;
  std::string settings_file;
  bool json = false;
  std::uint64_t memory_limit = 0;
};

void run_merge(const MergeOptions& options) {
  registration::MergeSettings settings = options.settings;
  if (!options.settings_file.empty()) {
    settings = read_settings_file<registration::MergeSettings>(options.settings_file);
    settings.threads = options.settings.threads;
  }
  store::Project project = store::Project::open(options.project);
  ProgressBar progress;
  const modeling::MergeCommandResult out =
      modeling::merge_project(project, settings, progress, memory_limit_of(options.memory_limit));
  if (options.json) {
    fmt::print("{}\n", modeling::result_json(out));
    return;
  }
  std::size_t kept = 0;
  for (const modeling::MergeCommandScan& s : out.scans) kept += s.counts.kept;
  fmt::print("{:>4}  {:<24} {:>10} {:>10} {:>10}\n", "id", "name", "in model", "kept", "redundant");
  for (const modeling::MergeCommandScan& s : out.scans) {
    fmt::print("{:>4}  {:<24} {:>10} {:>10} {:>10}\n", s.id, s.name, s.counts.in_model,
               s.counts.kept, s.counts.redundant);
  }
  fmt::print("merged model: {} of {} points kept ({:.2f} s); keep masks stored in {}\n", kept,
             out.points, out.seconds, options.project);
}

}  // namespace

void add_merge_command(CLI::App& app) {
  auto options = std::make_shared<MergeOptions>();
  CLI::App* command = app.add_subcommand(
      "merge",
      "Decide the merged model: keep each point only if no other scan sampled its surface more "
      "finely (seed 004 §4.3), and store a keep mask per scan (one command, undoable). Scans are "
      "never changed.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  add_settings_option(command, options->settings_file);
  add_threads_option(command, options->settings.threads);
  add_memory_limit_option(command, options->memory_limit);
  command->add_flag("--json", options->json, "Print one JSON object");
  command->callback([options] { run_merge(*options); });
}

}  // namespace scanbench::app
