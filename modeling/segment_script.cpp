#include "modeling/segment_script.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "modeling/segment_commands.hpp"

namespace scanbench::modeling {

namespace {

constexpr std::uintmax_t kMaxScriptBytes = 16u << 20;

// One op of the file, checked and typed.
struct Op {
  std::string name;
  std::optional<std::int64_t> scan;
  segmentation::Polyline points;                   // lasso, barrier
  Eigen::Vector2d seed = Eigen::Vector2d::Zero();  // seed, grow, add, subtract
  bool has_seed = true;  // grow, add, subtract: false = the last seed op's
  segmentation::GrowSettings grow;
  std::string text;                                       // commit, group, rename: the name
  nlohmann::json node;                                    // a NODE reference
  std::optional<nlohmann::json> parent;                   // given: a NODE or null
  std::vector<nlohmann::json> children;                   // group; merge: the objects
  DeletedPoints deleted_points = DeletedPoints::kToPool;  // delete
  std::size_t min_pixels = segmentation::ProposalSettings{}.min_pixels;  // auto
};

// Where in the script: "op 3 (grow)".
std::string where(std::size_t index, const std::string& name) {
  return "op " + std::to_string(index + 1) + (name.empty() ? "" : " (" + name + ")");
}

[[noreturn]] void refuse(const std::string& file, const std::string& at,
                         const std::string& problem) {
  core::FilePosition position;
  position.detail = at;
  throw core::InputError(file, position, problem);
}

// Reads the parts of one op; `bad` throws naming the op.
class OpReader {
 public:
  OpReader(const nlohmann::json& json, std::string file, std::string at)
      : json_(json), file_(std::move(file)), at_(std::move(at)) {}

  [[noreturn]] void bad(const std::string& problem) const { refuse(file_, at_, problem); }

  bool has(const char* key) const { return json_.contains(key); }

  std::string text(const char* key) const {
    if (!json_.contains(key) || !json_[key].is_string())
      bad(std::string("key \"") + key + "\" must be a string");
    return json_[key].get<std::string>();
  }

  double number(const char* key) const {
    if (!json_[key].is_number()) bad(std::string("key \"") + key + "\" must be a number");
    const double value = json_[key].get<double>();
    if (!std::isfinite(value)) bad(std::string("key \"") + key + "\" is not finite");
    return value;
  }

  Eigen::Vector2d point(const nlohmann::json& p, const char* key) const {
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
      bad(std::string("key \"") + key + "\" needs points [x, y]");
    }
    const Eigen::Vector2d v(p[0].get<double>(), p[1].get<double>());
    if (!v.allFinite()) bad(std::string("key \"") + key + "\" holds a point that is not finite");
    return v;
  }

  segmentation::Polyline points(std::size_t at_least) const {
    if (!json_.contains("points") || !json_["points"].is_array())
      bad("key \"points\" must be an array of [x, y]");
    segmentation::Polyline line;
    for (const nlohmann::json& p : json_["points"]) line.push_back(point(p, "points"));
    if (line.size() < at_least)
      bad("key \"points\" needs at least " + std::to_string(at_least) + " points");
    return line;
  }

  nlohmann::json node(const char* key, bool null_allowed) const {
    if (!json_.contains(key)) bad(std::string("key \"") + key + "\" is missing");
    const nlohmann::json& value = json_[key];
    if (value.is_number_integer() || value.is_string() || (null_allowed && value.is_null()))
      return value;
    bad(std::string("key \"") + key + "\" must be a node id or name" +
        (null_allowed ? ", or null" : ""));
  }

  const nlohmann::json& json() const { return json_; }

 private:
  const nlohmann::json& json_;
  std::string file_;
  std::string at_;
};

constexpr std::size_t kMaxVertices = 10000;  // per lasso or barrier: a hand-drawn line

// Each op and the keys it may have ("op" and "scan" besides): a misspelt
// key is refused, not silently left at its default.
const std::map<std::string, std::vector<std::string>>& op_keys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"lasso", {"points"}},
      {"barrier", {"points"}},
      {"clear", {}},
      {"seed", {"at"}},
      {"grow", {"seed", "channel", "tolerance"}},
      {"add", {"seed", "channel", "tolerance"}},
      {"subtract", {"seed", "channel", "tolerance"}},
      {"commit", {"name", "parent"}},
      {"group", {"name", "parent", "children"}},
      {"rename", {"node", "name"}},
      {"hide", {"node"}},
      {"show", {"node"}},
      {"reparent", {"node", "parent"}},
      {"delete", {"node", "points"}},
      {"ungroup", {"node"}},
      {"merge", {"nodes"}},
      {"separate", {"node"}},
      {"auto", {"group", "parent", "channel", "tolerance", "min_pixels"}},
      {"undo", {}},
      {"redo", {}}};
  return keys;
}

// Ops on pixels and the tools (read_pixel_op, Runner::apply_pixels); the
// others are on the tree or the journal.
bool is_pixel_op(const std::string& name) {
  static const std::vector<std::string> kPixelOps = {"lasso", "barrier", "clear",    "seed",
                                                     "grow",  "add",     "subtract", "auto"};
  return std::find(kPixelOps.begin(), kPixelOps.end(), name) != kPixelOps.end();
}

// The channel and tolerance of grow, add, subtract and auto.
segmentation::GrowSettings read_channel(const OpReader& in) {
  segmentation::Channel channel = segmentation::Channel::kNormal;
  if (in.has("channel")) {
    const std::optional<segmentation::Channel> named =
        segmentation::channel_from_name(in.text("channel"));
    if (!named) {
      in.bad("unknown channel \"" + in.text("channel") + "\" (range, color, intensity, normal)");
    }
    channel = *named;
  }
  segmentation::GrowSettings grow = segmentation::default_grow_settings(channel);
  if (in.has("tolerance")) {
    grow.tolerance = in.number("tolerance");
    if (grow.tolerance <= 0.0) in.bad("key \"tolerance\" must be positive");
  }
  return grow;
}

std::string read_name(const OpReader& in) {
  std::string name = in.text("name");
  if (name.empty()) in.bad("key \"name\" is empty");
  return name;
}

// Ops on pixels: lasso, barrier, grow, add, subtract, auto.
void read_pixel_op(const OpReader& in, Op& op) {
  if (op.name == "lasso" || op.name == "barrier") {
    op.points = in.points(op.name == "lasso" ? 3 : 1);
    if (op.points.size() > kMaxVertices) in.bad("more than 10000 points");
  } else if (op.name == "auto") {
    op.text = in.has("group") ? in.text("group") : "proposals";
    if (op.text.empty()) in.bad("key \"group\" is empty");
    if (in.has("parent")) op.parent = in.node("parent", true);
    op.grow = read_channel(in);
    if (in.has("min_pixels")) {
      if (!in.json()["min_pixels"].is_number_unsigned())
        in.bad("key \"min_pixels\" must be a count");
      op.min_pixels = in.json()["min_pixels"].get<std::size_t>();
    }
  } else if (op.name == "seed") {
    if (!in.has("at")) in.bad("key \"at\" is missing");
    op.seed = in.point(in.json()["at"], "at");
  } else if (op.name != "clear") {  // grow, add, subtract: at "seed", or the last seed op's
    op.has_seed = in.has("seed");
    if (op.has_seed) op.seed = in.point(in.json()["seed"], "seed");
    op.grow = read_channel(in);
  }
}

// Ops on the tree: commit, group, ungroup, merge, rename, hide, show,
// reparent, delete, separate.
void read_tree_op(const OpReader& in, Op& op) {
  if (op.name == "commit" || op.name == "group" || op.name == "rename") op.text = read_name(in);
  if (op.name != "commit" && op.name != "group" && op.name != "merge")
    op.node = in.node("node", false);
  if (op.name == "commit" || op.name == "group") {
    if (in.has("parent")) op.parent = in.node("parent", true);
  } else if (op.name == "reparent") {
    op.parent = in.node("parent", true);
  }
  if ((op.name == "group" && in.has("children")) || op.name == "merge") {
    const std::string key = op.name == "merge" ? "nodes" : "children";
    if (!in.has(key.c_str())) in.bad("key \"" + key + "\" is missing");
    const nlohmann::json& children = in.json()[key];
    if (!children.is_array()) in.bad("key \"" + key + "\" must be an array of nodes");
    for (const nlohmann::json& child : children) {
      if (!child.is_number_integer() && !child.is_string()) {
        in.bad("key \"" + key + "\" must hold node ids or names");
      }
      op.children.push_back(child);
    }
    if (op.name == "merge" && op.children.size() < 2) in.bad("merge needs two objects or more");
  }
  if (op.name == "delete") {
    const std::string points = in.has("points") ? in.text("points") : "pool";
    if (points != "pool" && points != "deleted") {
      in.bad("key \"points\" must be \"pool\" or \"deleted\"");
    }
    op.deleted_points = points == "pool" ? DeletedPoints::kToPool : DeletedPoints::kDeleted;
  }
}

Op read_op(const nlohmann::json& json, std::size_t index, const std::string& file) {
  if (!json.is_object() || !json.contains("op") || !json["op"].is_string()) {
    refuse(file, where(index, ""), "an op is an object with a string \"op\"");
  }
  Op op;
  op.name = json["op"].get<std::string>();
  const OpReader in(json, file, where(index, op.name));
  const auto known = op_keys().find(op.name);
  if (known == op_keys().end()) in.bad("unknown op \"" + op.name + "\"");
  for (const auto& [key, value] : json.items()) {
    const std::vector<std::string>& allowed = known->second;
    if (key != "op" && key != "scan" &&
        std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      in.bad("unknown key \"" + key + "\"");
    }
  }
  if (in.has("scan")) {
    if (!json["scan"].is_number_integer()) in.bad("key \"scan\" must be a scan id");
    op.scan = json["scan"].get<std::int64_t>();
  }
  if (is_pixel_op(op.name)) {
    read_pixel_op(in, op);
  } else if (op.name != "undo" && op.name != "redo") {
    read_tree_op(in, op);
  }
  return op;
}

nlohmann::json read_script(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) refuse(name, "", "is not a regular file");
  if (std::filesystem::file_size(file, error) > kMaxScriptBytes)
    refuse(name, "", "is larger than 16 MB");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw core::RuntimeFailure(name, {}, "cannot read the script");
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    core::FilePosition position;
    position.detail = "byte " + std::to_string(e.byte);
    throw core::InputError(name, position, "not JSON");
  }
}

// The script's state between ops, and what it did to the journal.
class Runner {
 public:
  Runner(Project& project, std::string file) : project_(project), file_(std::move(file)) {
    const std::vector<StoredScanSummary> scans = project.scans();
    if (!scans.empty()) scan_ = scans.front().id;
  }

  void set_default_scan(std::int64_t scan) { scan_ = scan; }

  nlohmann::json apply(const Op& op, const std::string& at);
  // Takes back what the script did; the empty string when all of it was,
  // else what stays.
  std::string roll_back() noexcept;

 private:
  nlohmann::json apply_pixels(const Op& op, const std::string& at);
  nlohmann::json apply_tree(const Op& op, const std::string& at);
  nlohmann::json apply_journal(const Op& op, const std::string& at);
  // The scan's size, or refused when there is no such scan.
  StoredScanSummary scan_of(const Op& op, const std::string& at) const;
  std::int64_t node_of(const nlohmann::json& reference, const std::string& at) const;
  std::optional<std::int64_t> parent_of(const nlohmann::json& reference,
                                        const std::string& at) const;
  void check_points(const segmentation::Polyline& line, const StoredScanSummary& scan,
                    const std::string& at) const;
  nlohmann::json made(std::int64_t command_id, nlohmann::json result) {
    actions_.push_back({Action::kMade, command_id});
    return {{"command", command_id}, {"result", std::move(result)}};
  }

  struct Action {
    enum Kind { kMade, kUndid, kRedid } kind;
    std::int64_t command_id;
  };

  Project& project_;
  std::string file_;
  std::optional<std::int64_t> scan_;
  segmentation::Constraints constraints_;
  std::optional<std::int64_t> constraints_scan_;  // the scan they were drawn on
  std::optional<Eigen::Vector2d> seed_;           // the last seed op's point
  std::vector<Action> actions_;
};

StoredScanSummary Runner::scan_of(const Op& op, const std::string& at) const {
  const std::optional<std::int64_t> scan = op.scan ? op.scan : scan_;
  if (!scan) refuse(file_, at, "the project has no scan");
  for (const StoredScanSummary& stored : project_.scans()) {
    if (stored.id == *scan) return stored;
  }
  refuse(file_, at, "no scan with id " + std::to_string(*scan));
}

std::int64_t Runner::node_of(const nlohmann::json& reference, const std::string& at) const {
  if (reference.is_number_integer()) return reference.get<std::int64_t>();
  const std::string name = reference.get<std::string>();
  std::optional<std::int64_t> found;
  for (const ObjectNode& node : project_.object_nodes()) {
    if (node.name != name) continue;
    if (found) refuse(file_, at, "more than one node is called \"" + name + "\": use its id");
    found = node.id;
  }
  if (!found) refuse(file_, at, "no node is called \"" + name + "\"");
  return *found;
}

std::optional<std::int64_t> Runner::parent_of(const nlohmann::json& reference,
                                              const std::string& at) const {
  if (reference.is_null()) return std::nullopt;
  return node_of(reference, at);
}

void Runner::check_points(const segmentation::Polyline& line, const StoredScanSummary& scan,
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

nlohmann::json Runner::apply_pixels(const Op& op, const std::string& at) {
  if (op.name == "clear") {
    constraints_ = {};
    constraints_scan_.reset();
    return {{"command", nullptr}, {"result", nlohmann::json::object()}};
  }
  if (op.name == "seed") {
    seed_ = op.seed;
    return {{"command", nullptr}, {"result", {{"seed", {op.seed.x(), op.seed.y()}}}}};
  }
  const StoredScanSummary scan = scan_of(op, at);
  const bool drawing = op.name == "lasso" || op.name == "barrier";
  if ((drawing || op.name != "auto") && constraints_scan_ && *constraints_scan_ != scan.id) {
    refuse(file_, at,
           "the lasso and barriers were drawn on scan " + std::to_string(*constraints_scan_) +
               ": \"clear\" them first");
  }
  if (drawing) {
    check_points(op.points, scan, at);
    if (op.name == "lasso") {
      constraints_.lasso = op.points;
    } else {
      constraints_.barriers.push_back(op.points);
    }
    constraints_scan_ = scan.id;
    return {{"command", nullptr}, {"result", {{"points", op.points.size()}}}};
  }
  if (op.name == "auto") {
    ProposeSettings s;
    s.scan_id = scan.id;
    s.group_name = op.text;
    s.parent = op.parent ? parent_of(*op.parent, at) : std::nullopt;
    s.proposals.grow = op.grow;
    s.proposals.min_pixels = op.min_pixels;
    const SeparateResult r = propose_objects(project_, s);
    return made(r.command_id, {{"proposals", r.nodes.size()}});
  }
  if (!op.has_seed && !seed_) refuse(file_, at, "no \"seed\": give one, or a seed op before");
  const Eigen::Vector2d seed = op.has_seed ? op.seed : *seed_;
  SelectSettings s;
  s.scan_id = scan.id;
  s.seed_col = static_cast<int>(std::llround(std::clamp(seed.x(), -1.0, 1e9)));
  s.seed_row = static_cast<int>(std::llround(std::clamp(seed.y(), -1.0, 1e9)));
  s.mode = op.name == "grow"  ? SelectMode::kReplace
           : op.name == "add" ? SelectMode::kAdd
                              : SelectMode::kSubtract;
  s.grow = op.grow;
  s.constraints = constraints_;
  const SelectResult r = select_region(project_, s);
  return made(r.command_id, {{"region_pixels", r.region_pixels},
                             {"selected_pixels", r.selected_pixels},
                             {"seed_open", r.seed_open}});
}

nlohmann::json Runner::apply_tree(const Op& op, const std::string& at) {
  if (op.name == "commit") {
    const std::optional<std::int64_t> parent = op.parent ? parent_of(*op.parent, at) : std::nullopt;
    const NodeCommandResult r = commit_selection(project_, {scan_of(op, at).id, op.text, parent});
    return made(r.command_id, {{"node", r.node_id}});
  }
  if (op.name == "group") {
    GroupSettings s{op.text, op.parent ? parent_of(*op.parent, at) : std::nullopt, {}};
    for (const nlohmann::json& child : op.children) s.children.push_back(node_of(child, at));
    const NodeCommandResult r = group_nodes(project_, s);
    return made(r.command_id, {{"node", r.node_id}});
  }
  if (op.name == "separate") {
    const SeparateResult r = separate_object(project_, {node_of(op.node, at), scan_of(op, at).id});
    return made(r.command_id, {{"nodes", r.nodes}});
  }
  if (op.name == "merge") {
    MergeSettings s;
    for (const nlohmann::json& object : op.children) s.objects.push_back(node_of(object, at));
    const NodeCommandResult r = merge_objects(project_, s);
    return made(r.command_id, {{"node", r.node_id}});
  }
  if (op.name == "ungroup") {
    const UngroupResult r = ungroup_node(project_, node_of(op.node, at));
    return made(r.command_id, {{"children", r.children}});
  }
  if (op.name == "delete") {
    const NodeCommandResult r = delete_node(project_, {node_of(op.node, at), op.deleted_points});
    return made(r.command_id, {{"node", r.node_id}});
  }
  NodeEdit edit;  // rename, hide, show, reparent
  edit.node = node_of(op.node, at);
  if (op.name == "rename") edit.name = op.text;
  if (op.name == "hide" || op.name == "show") edit.hidden = op.name == "hide";
  if (op.name == "reparent") edit.parent = parent_of(*op.parent, at);
  const NodeCommandResult r = edit_node(project_, edit);
  return made(r.command_id, {{"node", r.node_id}});
}

nlohmann::json Runner::apply_journal(const Op& op, const std::string& at) {
  const bool undo = op.name == "undo";
  const std::optional<CommandRecord> changed = undo ? project_.undo() : project_.redo();
  if (!changed) refuse(file_, at, undo ? "nothing to undo" : "nothing to redo");
  actions_.push_back({undo ? Action::kUndid : Action::kRedid, changed->id});
  return {{"command", changed->id}, {"result", {{undo ? "undid" : "redid", changed->name}}}};
}

nlohmann::json Runner::apply(const Op& op, const std::string& at) {
  if (op.name == "undo" || op.name == "redo") return apply_journal(op, at);
  if (is_pixel_op(op.name)) return apply_pixels(op, at);
  return apply_tree(op, at);
}

// Takes back what the script did, newest first: its commands undone, its
// undos redone, its redos undone, each only when it is exactly that command
// (Project::undo/redo with `only`). It stops at the first that is not: an
// undo the script made before one of its own commands cannot come back
// (that command ended the redo chain), and another process may have written
// meanwhile.
std::string Runner::roll_back() noexcept {
  std::string left;
  try {
    for (auto action = actions_.rbegin(); action != actions_.rend(); ++action) {
      const bool ok = action->kind == Action::kUndid
                          ? project_.redo(action->command_id).has_value()
                          : project_.undo(action->command_id).has_value();
      if (!ok) {
        left = "; what the script did up to command " + std::to_string(action->command_id) +
               " could not be taken back";
        break;
      }
    }
  } catch (const std::exception& error) {
    left = std::string("; taking back what the script did failed: ") + error.what();
  }
  actions_.clear();
  return left;
}

}  // namespace

SegmentScriptResult run_segment_script(Project& project, const std::filesystem::path& script) {
  const std::string file = script.string();
  const nlohmann::json document = read_script(script);
  if (!document.is_object() || !document.contains("ops") || !document["ops"].is_array()) {
    refuse(file, "", "a script is an object with an array \"ops\"");
  }
  std::vector<Op> ops;
  for (std::size_t k = 0; k < document["ops"].size(); ++k)
    ops.push_back(read_op(document["ops"][k], k, file));
  Runner runner(project, file);
  if (document.contains("scan")) {
    if (!document["scan"].is_number_integer()) refuse(file, "key \"scan\"", "must be a scan id");
    runner.set_default_scan(document["scan"].get<std::int64_t>());
  }
  SegmentScriptResult result;
  for (std::size_t k = 0; k < ops.size(); ++k) {
    const std::string at = where(k, ops[k].name);
    try {
      nlohmann::json done = runner.apply(ops[k], at);
      done["op"] = ops[k].name;
      result.ops.push_back(std::move(done));
    } catch (const core::InputError& error) {
      // The script's file, unless the project itself is at fault; the op either way.
      const std::string left = runner.roll_back();
      core::FilePosition position = error.position();
      if (position.detail.rfind("op ", 0) != 0) {
        position.detail = at + (position.detail.empty() ? "" : ", " + position.detail);
      }
      throw core::InputError(error.file().empty() ? file : error.file(), position,
                             error.problem() + left);
    } catch (const core::RuntimeFailure& error) {
      const std::string left = runner.roll_back();
      core::FilePosition position = error.position();
      position.detail = at + (position.detail.empty() ? "" : ", " + position.detail);
      throw core::RuntimeFailure(error.file(), position, error.problem() + left);
    } catch (...) {
      runner.roll_back();
      throw;
    }
  }
  return result;
}

}  // namespace scanbench::modeling
