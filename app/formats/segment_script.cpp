#include "app/formats/segment_script.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/formats/json_input.hpp"
#include "core/errors.hpp"
#include "modeling/selection_commands.hpp"
#include "modeling/selection_tools.hpp"

namespace scanbench::app {

namespace {

// Every refusal ends with it: the batch is rolled back whole.
constexpr const char* kNothingStored = "; the script stored nothing";

[[noreturn]] void refuse(const std::string& file, const std::string& at,
                         const std::string& problem) {
  acquisition::JsonPlace{file, at}.refuse(problem);
}

// The script's state between ops, and what it did to the journal.
class Runner {
 public:
  Runner(store::Project& project, std::string file) : project_(project), file_(std::move(file)) {
    const std::vector<store::StoredScanSummary> scans = project.scans();
    if (!scans.empty()) scan_ = scans.front().id;
  }

  void set_default_scan(std::int64_t scan) { scan_ = scan; }

  nlohmann::json apply(const ScriptOp& op, const std::string& at);
  // At the script's end: the selections it left, kept in the project
  // unless that would end the redo chain (SelectionTools::keep).
  modeling::SelectionTools::Kept keep_selections() { return tools_.keep(project_, true); }

 private:
  nlohmann::json apply_pixels(const ScriptOp& op, const std::string& at);
  nlohmann::json apply_proposals(const ScriptOp& op, std::int64_t scan_id, const std::string& at);
  nlohmann::json apply_tree(const ScriptOp& op, const std::string& at);
  nlohmann::json apply_journal(const ScriptOp& op, const std::string& at);
  // The scan's size, or refused when there is no such scan.
  store::StoredScanSummary scan_of(const ScriptOp& op, const std::string& at) const;
  std::int64_t node_of(const nlohmann::json& reference, const std::string& at) const;
  std::optional<std::int64_t> parent_of(const nlohmann::json& reference,
                                        const std::string& at) const;
  void check_points(const segmentation::Polyline& line, const store::StoredScanSummary& scan,
                    const std::string& at) const;
  static nlohmann::json made(std::int64_t command_id, nlohmann::json result) {
    return {{"command", command_id}, {"result", std::move(result)}};
  }

  store::Project& project_;
  std::string file_;
  std::optional<std::int64_t> scan_;
  // The lasso, the barriers, the last seed op's point and the selections.
  modeling::SelectionTools tools_;
};

store::StoredScanSummary Runner::scan_of(const ScriptOp& op, const std::string& at) const {
  const std::optional<std::int64_t> scan = op.scan ? op.scan : scan_;
  if (!scan) refuse(file_, at, "the project has no scan");
  for (const store::StoredScanSummary& stored : project_.scans()) {
    if (stored.id == *scan) return stored;
  }
  refuse(file_, at, "no scan with id " + std::to_string(*scan));
}

std::int64_t Runner::node_of(const nlohmann::json& reference, const std::string& at) const {
  if (reference.is_number_integer()) return reference.get<std::int64_t>();
  const std::string name = reference.get<std::string>();
  const std::vector<std::int64_t> found = project_.nodes_named(name);
  if (found.size() > 1)
    refuse(file_, at, "more than one node is called \"" + name + "\": use its id");
  if (found.empty()) refuse(file_, at, "no node is called \"" + name + "\"");
  return found.front();
}

std::optional<std::int64_t> Runner::parent_of(const nlohmann::json& reference,
                                              const std::string& at) const {
  if (reference.is_null()) return std::nullopt;
  return node_of(reference, at);
}

void Runner::check_points(const segmentation::Polyline& line, const store::StoredScanSummary& scan,
                          const std::string& at) const {
  const segmentation::GridShape shape{scan.summary.rows, scan.summary.columns, false};
  for (const Eigen::Vector2d& v : line) {
    if (!segmentation::within_reach(shape, v)) {
      refuse(file_, at,
             "point (" + std::to_string(v.x()) + ", " + std::to_string(v.y()) +
                 ") lies more than a grid size away from the scan's grid");
    }
  }
}

nlohmann::json Runner::apply_pixels(const ScriptOp& op, const std::string& at) {
  if (op.name == "clear") {
    tools_.clear();
    return {{"command", nullptr}, {"result", nlohmann::json::object()}};
  }
  if (op.name == "seed") {
    tools_.set_seed(op.seed);
    return {{"command", nullptr}, {"result", {{"seed", {op.seed.x(), op.seed.y()}}}}};
  }
  const store::StoredScanSummary scan = scan_of(op, at);
  if (op.name != "auto" && tools_.scan() && *tools_.scan() != scan.id) {
    refuse(file_, at,
           "the lasso and barriers were drawn on scan " + std::to_string(*tools_.scan()) +
               ": \"clear\" them first");
  }
  if (op.name == "lasso" || op.name == "barrier") {
    check_points(op.points, scan, at);
    if (op.name == "lasso") {
      tools_.set_lasso(scan.id, op.points);
    } else {
      tools_.add_barrier(scan.id, op.points);
    }
    return {{"command", nullptr}, {"result", {{"points", op.points.size()}}}};
  }
  if (op.name == "auto") return apply_proposals(op, scan.id, at);
  if (!op.has_seed && !tools_.seed())
    refuse(file_, at, "no \"seed\": give one, or a seed op before");
  const modeling::SelectMode mode = op.name == "grow"  ? modeling::SelectMode::kReplace
                                    : op.name == "add" ? modeling::SelectMode::kAdd
                                                       : modeling::SelectMode::kSubtract;
  const modeling::SelectSettings settings =
      tools_.select_at(scan.id, op.has_seed ? op.seed : *tools_.seed(), mode, op.grow);
  const modeling::SelectResult r = tools_.select(project_, settings);
  // A selection is session state: a grow is no command.
  nlohmann::json done = {{"command", nullptr},
                         {"result",
                          {{"region_pixels", r.region_pixels},
                           {"selected_pixels", r.selected_pixels},
                           {"seed_open", r.seed_open}}}};
  if (!r.seed_open) done["result"]["refused"] = r.refused;
  return done;
}

nlohmann::json Runner::apply_proposals(const ScriptOp& op, std::int64_t scan_id,
                                       const std::string& at) {
  modeling::ProposeSettings s;
  s.scan_id = scan_id;
  s.group_name = op.text;
  s.parent = op.parent ? parent_of(*op.parent, at) : std::nullopt;
  s.proposals.grow = op.grow;
  s.proposals.min_pixels = op.min_pixels;
  const modeling::SeparateResult r = modeling::propose_objects(project_, s);
  return made(r.command_id, {{"proposals", r.nodes.size()}});
}

nlohmann::json Runner::apply_tree(const ScriptOp& op, const std::string& at) {
  if (op.name == "commit") {
    const std::optional<std::int64_t> parent = op.parent ? parent_of(*op.parent, at) : std::nullopt;
    const modeling::NodeCommandResult r =
        tools_.commit(project_, tools_.commit_of(scan_of(op, at).id, op.text, parent));
    return made(r.command_id, {{"node", r.node_id}});
  }
  if (op.name == "group") {
    modeling::GroupSettings s{op.text, op.parent ? parent_of(*op.parent, at) : std::nullopt, {}};
    for (const nlohmann::json& child : op.children) s.children.push_back(node_of(child, at));
    const modeling::NodeCommandResult r = modeling::group_nodes(project_, s);
    return made(r.command_id, {{"node", r.node_id}});
  }
  if (op.name == "separate") {
    const modeling::SeparateResult r =
        modeling::separate_object(project_, {node_of(op.node, at), scan_of(op, at).id});
    return made(r.command_id, {{"nodes", r.nodes}});
  }
  if (op.name == "merge") {
    modeling::MergeSettings s;
    for (const nlohmann::json& object : op.children) s.objects.push_back(node_of(object, at));
    const modeling::NodeCommandResult r = modeling::merge_objects(project_, s);
    return made(r.command_id, {{"node", r.node_id}});
  }
  if (op.name == "ungroup") {
    const modeling::UngroupResult r = modeling::ungroup_node(project_, node_of(op.node, at));
    return made(r.command_id, {{"children", r.children}});
  }
  if (op.name == "delete") {
    const modeling::NodeCommandResult r =
        modeling::delete_node(project_, {node_of(op.node, at), op.deleted_points, {}});
    return made(r.command_id, {{"node", r.node_id}});
  }
  modeling::NodeEdit edit;  // rename, hide, show, reparent
  edit.node = node_of(op.node, at);
  if (op.name == "rename") edit.name = op.text;
  if (op.name == "hide" || op.name == "show") edit.hidden = op.name == "hide";
  if (op.name == "reparent") edit.parent = parent_of(*op.parent, at);
  const modeling::NodeCommandResult r = modeling::edit_node(project_, edit);
  return made(r.command_id, {{"node", r.node_id}});
}

nlohmann::json Runner::apply_journal(const ScriptOp& op, const std::string& at) {
  const bool undo = op.name == "undo";
  // The grows since the last command first: they are the script's own state.
  if (undo ? tools_.undo_selection() : tools_.redo_selection())
    return {{"command", nullptr}, {"result", {{undo ? "undid" : "redid", "grow"}}}};
  if (!undo && tools_.grown_since_command())
    refuse(file_, at, "nothing to redo: the selection grew since the undo");
  const std::optional<store::CommandRecord> changed = undo ? project_.undo() : project_.redo();
  if (!changed) refuse(file_, at, undo ? "nothing to undo" : "nothing to redo");
  if (undo) {
    tools_.command_undone(project_, changed->id);
  } else {
    tools_.command_redone(project_, changed->id);
  }
  return {{"command", changed->id}, {"result", {{undo ? "undid" : "redid", changed->name}}}};
}

nlohmann::json Runner::apply(const ScriptOp& op, const std::string& at) {
  if (op.name == "undo" || op.name == "redo") return apply_journal(op, at);
  if (is_pixel_op(op.name)) {
    nlohmann::json done = apply_pixels(op, at);
    if (!done["command"].is_null()) tools_.command_ran();  // proposals
    return done;
  }
  nlohmann::json done = apply_tree(op, at);
  if (op.name != "commit") tools_.command_ran();
  return done;
}

}  // namespace

SegmentScriptResult run_segment_script(store::Project& project, const std::filesystem::path& path) {
  return run_segment_script(project, read_segment_script(path));
}

SegmentScriptResult run_segment_script(store::Project& project, const SegmentScript& script) {
  const std::string& file = script.file;
  // One unit: a refused op rolls back every op before it, undos and redos
  // included, and no other process writes in between.
  store::Project::Batch batch = project.begin_batch();
  Runner runner(project, file);
  if (script.scan) runner.set_default_scan(*script.scan);
  SegmentScriptResult result;
  for (std::size_t k = 0; k < script.ops.size(); ++k) {
    const std::string at = script_op_place(k, script.ops[k].name);
    try {
      nlohmann::json done = runner.apply(script.ops[k], at);
      done["op"] = script.ops[k].name;
      result.ops.push_back(std::move(done));
    } catch (const core::InputError& error) {
      // The script's file, unless the project itself is at fault; the op either way.
      core::FilePosition position = error.position();
      if (position.detail.rfind("op ", 0) != 0) {
        position.detail = at + (position.detail.empty() ? "" : ", " + position.detail);
      }
      throw core::InputError(error.file().empty() ? file : error.file(), position,
                             error.problem() + kNothingStored);
    } catch (const core::RuntimeFailure& error) {
      core::FilePosition position = error.position();
      position.detail = at + (position.detail.empty() ? "" : ", " + position.detail);
      throw core::RuntimeFailure(error.file(), position, error.problem() + kNothingStored);
    }
  }
  // A selection left uncommitted stays for the next script or the workbench.
  const modeling::SelectionTools::Kept kept = runner.keep_selections();
  result.kept_selections = kept.command_id;
  result.selections_held_back = kept.held_back;
  batch.commit();
  return result;
}

}  // namespace scanbench::app
