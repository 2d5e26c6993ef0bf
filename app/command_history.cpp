// scanbench undo PROJECT, scanbench redo PROJECT,
// scanbench history PROJECT [--json | --settings ID]
#include <fmt/core.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::app {
namespace {

struct HistoryOptions {
  std::string project;
  bool json = false;
  std::optional<std::int64_t> settings_of;
};

const char* state_name(store::CommandState state) {
  switch (state) {
    case store::CommandState::kDone:
      return "done";
    case store::CommandState::kUndone:
      return "undone";
    case store::CommandState::kPending:
      return "pending";
    case store::CommandState::kInterrupted:
      return "interrupted";
  }
  return "";
}

nlohmann::json parsed(const std::string& text) {
  return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
}

// One line on what a command did, from its result. Longer than 60 lines,
// but flat: one case per command name, read at a glance.
std::string summary(const store::CommandRecord& c) {
  if (c.state == store::CommandState::kInterrupted)
    return "its process ended before it finished: nothing was stored";
  const nlohmann::json result = parsed(c.result);
  const nlohmann::json settings = parsed(c.settings);
  if (!result.is_object()) return "";
  if (c.name == "migrate" && settings.contains("from_schema_version")) {
    return fmt::format("data stored before the journal (schema version {})",
                       settings["from_schema_version"].dump());
  }
  if (c.name == "import" && result.contains("scans")) {
    return fmt::format("{} scan(s)", result["scans"].size());
  }
  if (c.name == "geometry" && result.contains("scans")) {
    return fmt::format("{} scan(s)", result["scans"].size());
  }
  if (c.name == "register" && result.contains("overall")) {
    const nlohmann::json& overall = result["overall"];
    return fmt::format("rms {:.2f} mm, {}", 1000.0 * overall.value("rms_m", 0.0),
                       overall.value("converged", false) ? "converged" : "not converged");
  }
  if (c.name == "merge" && result.contains("kept")) {
    return fmt::format("{} of {} points kept", result.value("kept", 0), result.value("points", 0));
  }
  if (c.name == "keep_selection" && result.contains("scans") && result["scans"].is_object()) {
    std::string scans;
    for (const auto& [scan, pixels] : result["scans"].items())
      scans += fmt::format("{}scan {}: {} pixels", scans.empty() ? "" : ", ", scan, pixels.dump());
    return "selection kept: " + scans;
  }
  if (c.name == "select" && result.contains("selected_pixels")) {  // in older journals
    return fmt::format("scan {}: {} pixels selected", settings.value("scan", 0),
                       result.value("selected_pixels", 0));
  }
  if (c.name == "commit" && result.contains("node")) {
    return fmt::format("object {} \"{}\", {} points", result.value("node", 0),
                       core::one_line(settings.value("name", ""), core::kMaxMessagePart),
                       result.value("points", 0));
  }
  if ((c.name == "group" || c.name == "edit") && result.contains("node")) {
    return fmt::format("node {}", result.value("node", 0));
  }
  if (c.name == "merge_objects" && result.contains("merged")) {
    return fmt::format("{} object(s) merged into object {}", result.value("merged", 0),
                       result.value("node", 0));
  }
  if (c.name == "ungroup" && result.contains("children")) {
    return fmt::format("group {} dissolved, {} child(ren) moved up", result.value("node", 0),
                       result["children"].size());
  }
  if (c.name == "separate" && result.contains("nodes")) {
    return fmt::format("{} part(s)", result["nodes"].size());
  }
  if (c.name == "propose" && result.contains("proposals")) {
    return fmt::format("{} proposal(s), {} points", result.value("proposals", 0),
                       result.value("pixels", 0));
  }
  if ((c.name == "recolor" || c.name == "clone") && result.contains("node")) {
    const std::string color = result.contains("color") ? result["color"].dump() : "{}";
    return fmt::format("node {}: {}", result.value("node", 0), color);
  }
  if (c.name == "harmonize" && result.contains("pairs")) {
    return fmt::format("{} colour pairs, mean ΔE {:.2f} → {:.2f}", result.value("pairs", 0),
                       result.value("delta_e_before", 0.0), result.value("delta_e_after", 0.0));
  }
  if (c.name == "measure" && result.contains("measurements")) {
    return fmt::format("{}: {} measurement(s)",
                       core::one_line(settings.value("what", ""), core::kMaxMessagePart),
                       result["measurements"].size());
  }
  if (c.name == "delete" && result.contains("nodes")) {
    return fmt::format("{} node(s), points to the {}", result["nodes"].size(),
                       settings.value("points", "pool") == "pool" ? "pool" : "deleted");
  }
  return "";
}

nlohmann::json to_json(const store::CommandRecord& c) {
  return {{"id", c.id},
          {"name", c.name},
          {"state", state_name(c.state)},
          {"undoable", c.undoable},
          {"created_at", c.created_at},
          {"settings", parsed(c.settings)},
          {"result", parsed(c.result)}};
}

void run_history(const HistoryOptions& options) {
  const store::Project project = store::Project::open_for_reading(options.project);
  const std::vector<store::CommandRecord> history = project.history();
  if (options.settings_of) {
    for (const store::CommandRecord& c : history) {
      if (c.id != *options.settings_of) continue;
      fmt::print("{}\n",
                 parsed(c.settings).dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
      return;
    }
    throw core::InputError(options.project, {},
                           "has no command " + std::to_string(*options.settings_of));
  }
  if (options.json) {
    nlohmann::json commands = nlohmann::json::array();
    for (const store::CommandRecord& c : history) commands.push_back(to_json(c));
    fmt::print("{}\n", nlohmann::json{{"commands", commands}}.dump(
                           2, ' ', false, nlohmann::json::error_handler_t::replace));
    return;
  }
  fmt::print("{:>4}  {:<11} {:<10} {:<24}  {}\n", "id", "state", "command", "at (UTC)", "what");
  for (const store::CommandRecord& c : history) {
    fmt::print("{:>4}  {:<11} {:<10} {:<24}  {}\n", c.id, state_name(c.state), c.name, c.created_at,
               summary(c));
  }
}

void run_undo(const std::string& path) {
  store::Project project = store::Project::open(path);
  const std::optional<store::CommandRecord> undone = project.undo();
  if (!undone) {
    // undo() declines only when no command is done or the newest done one
    // is an older project's history.
    bool any_done = false;
    for (const store::CommandRecord& c : project.history()) {
      any_done = any_done || c.state == store::CommandState::kDone;
    }
    throw core::InputError(path, {},
                           any_done ? "nothing to undo: what is left was stored before this "
                                      "project had a journal (schema version 4)"
                                    : "nothing to undo");
  }
  fmt::print("undid {} {} ({}); `scanbench redo` brings it back\n", undone->id, undone->name,
             undone->created_at);
}

void run_redo(const std::string& path) {
  store::Project project = store::Project::open(path);
  const std::optional<store::CommandRecord> redone = project.redo();
  if (!redone) throw core::InputError(path, {}, "nothing to redo");
  fmt::print("redid {} {} ({})\n", redone->id, redone->name, redone->created_at);
}

CLI::Option* add_project(CLI::App* command, std::string& project) {
  return command->add_option("project", project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
}

}  // namespace

void add_history_commands(CLI::App& app) {
  auto options = std::make_shared<HistoryOptions>();
  CLI::App* history = app.add_subcommand(
      "history", "List the project's commands, oldest first, with their settings and results.");
  add_project(history, options->project);
  CLI::Option* json = history->add_flag("--json", options->json, "Print one JSON object");
  history
      ->add_option("--settings", options->settings_of,
                   "Print only the settings of command ID, as `--settings FILE` of geometry, "
                   "register, merge and harmonize reads them")
      ->excludes(json);
  history->callback([options] { run_history(*options); });

  auto undo_project = std::make_shared<std::string>();
  CLI::App* undo = app.add_subcommand(
      "undo",
      "Undo the newest command (import, geometry, register, merge, …); works across "
      "sessions and processes.");
  add_project(undo, *undo_project);
  undo->callback([undo_project] { run_undo(*undo_project); });

  auto redo_project = std::make_shared<std::string>();
  CLI::App* redo = app.add_subcommand("redo",
                                      "Redo the oldest undone command. A new command ends the redo "
                                      "chain: what was undone before it cannot be redone.");
  add_project(redo, *redo_project);
  redo->callback([redo_project] { run_redo(*redo_project); });
}

}  // namespace scanbench::app
