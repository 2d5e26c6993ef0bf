// scanbench check PROJECT [--json]
#include <fmt/core.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::app {
namespace {

struct CheckOptions {
  std::string project;
  bool json = false;
};

void run_check(const CheckOptions& options) {
  // A diagnosis never changes what it diagnoses: no migration, no recovery.
  const store::Project project = store::Project::open_read_only(options.project);
  const store::Project::CheckReport report = project.check();
  if (options.json) {
    fmt::print("{}\n", nlohmann::json{{"damage", report.damage},
                                      {"records", report.records},
                                      {"layers", report.layers},
                                      {"ok", report.damage.empty()}}
                           .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  } else {
    for (const std::string& line : report.damage) fmt::print("damaged: {}\n", line);
  }
  if (!report.damage.empty()) {
    throw core::InputError(options.project, {},
                           "project is damaged: " + std::to_string(report.damage.size()) +
                               " problem(s), listed on stdout");
  }
  if (!options.json) {
    fmt::print("{}: ok ({} records and {} layers checked)\n", options.project, report.records,
               report.layers);
  }
}

}  // namespace

void add_check_command(CLI::App& app) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* command = app.add_subcommand(
      "check",
      "Verify a whole project: SQLite's integrity check, every record's checksum, every layer "
      "decoded against its own. Exit 2, naming each damaged part, when anything is damaged.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_flag("--json", options->json, "Print one JSON object");
  command->callback([options] { run_check(*options); });
}

}  // namespace scanbench::app
