// scanbench segment PROJECT --script OPS.json [--json]
#include <fmt/core.h>

#include <memory>
#include <string>

#include "app/commands.hpp"
#include "app/formats/segment_script.hpp"

namespace scanbench::app {
namespace {

struct SegmentOptions {
  std::string project;
  std::string script;
  bool json = false;
};

void run_segment(const SegmentOptions& options) {
  // Bad input first: a refused file never opens (nor migrates) the project.
  const SegmentScript script = read_segment_script(options.script);
  store::Project project = store::Project::open(options.project);
  const SegmentScriptResult result = run_segment_script(project, script);
  if (options.json) {
    nlohmann::json out = {{"ops", result.ops},
                          {"kept_selections", nullptr},
                          {"selections_held_back", result.selections_held_back}};
    if (result.kept_selections != 0) out["kept_selections"] = result.kept_selections;
    fmt::print("{}\n", out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
    return;
  }
  for (std::size_t k = 0; k < result.ops.size(); ++k) {
    const nlohmann::json& op = result.ops[k];
    fmt::print("{:>4}  {:<9} {:>8}  {}\n", k + 1, op["op"].get<std::string>(),
               op["command"].is_null() ? std::string("-") : op["command"].dump(),
               op["result"].dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  if (result.kept_selections != 0) {
    fmt::print("the selection left uncommitted is kept in the project (command {})\n",
               result.kept_selections);
  }
  if (result.selections_held_back) {
    fmt::print(
        "the selection left uncommitted is not kept: keeping it would end the redo "
        "chain (redo, or commit it, first)\n");
  }
  fmt::print("{} op(s) applied to {}; `scanbench objects` shows the tree\n", result.ops.size(),
             options.project);
}

}  // namespace

void add_segment_command(CLI::App& app) {
  auto options = std::make_shared<SegmentOptions>();
  CLI::App* command = app.add_subcommand(
      "segment",
      "Segment scans into the object tree from a script of the workbench's operations (lasso, "
      "barrier, grow, add, subtract, commit, group, ungroup, merge, rename, hide, show, reparent, "
      "delete, separate, auto, undo, redo). Grows build the selection and write nothing; every "
      "other change is one undoable command, and a selection left uncommitted is kept for the "
      "next session. A refused script changes nothing.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--script", options->script, "The operations, as JSON (docs/segmentation.md)")
      ->required();
  command->add_flag("--json", options->json, "Print one JSON object");
  command->callback([options] { run_segment(*options); });
}

}  // namespace scanbench::app
