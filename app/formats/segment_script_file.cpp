#include "app/formats/segment_script_file.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "acquisition/formats/json_input.hpp"
#include "core/errors.hpp"

namespace scanbench::app {

namespace {

constexpr std::uintmax_t kMaxScriptBytes = 16u << 20;

[[noreturn]] void refuse(const std::string& file, const std::string& at,
                         const std::string& problem) {
  acquisition::JsonPlace{file, at}.refuse(problem);
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
    if (null_allowed && value.is_null()) return value;
    return node_reference(value, key);
  }

  // A NODE: a node id (a whole number a membership layer can name) or a name.
  nlohmann::json node_reference(const nlohmann::json& value, const std::string& key) const {
    if (value.is_string()) return value;
    if (!value.is_number()) bad("key \"" + key + "\" must hold node ids or names");
    return acquisition::whole_number(value, 1, std::int64_t{store::kDeletedPoints} - 1,
                                     {file_, at_}, "a node id in key \"" + key + "\"");
  }

  const nlohmann::json& json() const { return json_; }
  const std::string& file() const { return file_; }
  const std::string& at() const { return at_; }

 private:
  const nlohmann::json& json_;
  std::string file_;
  std::string at_;
};

constexpr std::size_t kMaxVertices = 10000;  // per lasso or barrier: a hand-drawn line

// Ops per script: a long session of clicks, far from the hours a script of
// 10^5 ops would hold the project's write lock.
constexpr std::size_t kMaxOps = 10000;

std::int64_t read_scan_id(const nlohmann::json& value, const acquisition::JsonPlace& place) {
  return acquisition::whole_number(value, 1, std::numeric_limits<std::int64_t>::max(), place,
                                   "key \"scan\" (a scan id)");
}

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
void read_pixel_op(const OpReader& in, ScriptOp& op) {
  if (op.name == "lasso" || op.name == "barrier") {
    op.points = in.points(op.name == "lasso" ? 3 : 1);
    if (op.points.size() > kMaxVertices) in.bad("more than 10000 points");
  } else if (op.name == "auto") {
    op.text = in.has("group") ? in.text("group") : "proposals";
    if (op.text.empty()) in.bad("key \"group\" is empty");
    if (in.has("parent")) op.parent = in.node("parent", true);
    op.grow = read_channel(in);
    if (in.has("min_pixels")) {
      op.min_pixels = static_cast<std::size_t>(
          acquisition::whole_number(in.json()["min_pixels"], 1, std::int64_t{1} << 40,
                                    {in.file(), in.at()}, "key \"min_pixels\""));
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
void read_tree_op(const OpReader& in, ScriptOp& op) {
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
    for (const nlohmann::json& child : children)
      op.children.push_back(in.node_reference(child, key));
    if (op.name == "merge" && op.children.size() < 2) in.bad("merge needs two objects or more");
  }
  if (op.name == "delete") {
    const std::string points = in.has("points") ? in.text("points") : "pool";
    if (points != "pool" && points != "deleted") {
      in.bad("key \"points\" must be \"pool\" or \"deleted\"");
    }
    op.deleted_points =
        points == "pool" ? modeling::DeletedPoints::kToPool : modeling::DeletedPoints::kDeleted;
  }
}

ScriptOp read_op(const nlohmann::json& json, std::size_t index, const std::string& file) {
  if (!json.is_object() || !json.contains("op") || !json["op"].is_string()) {
    refuse(file, script_op_place(index, ""), "an op is an object with a string \"op\"");
  }
  ScriptOp op;
  op.name = json["op"].get<std::string>();
  const OpReader in(json, file, script_op_place(index, op.name));
  const auto known = op_keys().find(op.name);
  if (known == op_keys().end()) in.bad("unknown op \"" + op.name + "\"");
  for (const auto& [key, value] : json.items()) {
    const std::vector<std::string>& allowed = known->second;
    if (key != "op" && key != "scan" &&
        std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      in.bad("unknown key \"" + key + "\"");
    }
  }
  if (in.has("scan")) op.scan = read_scan_id(json["scan"], {file, script_op_place(index, op.name)});
  if (is_pixel_op(op.name)) {
    read_pixel_op(in, op);
  } else if (op.name != "undo" && op.name != "redo") {
    read_tree_op(in, op);
  }
  return op;
}

}  // namespace

std::string script_op_place(std::size_t index, const std::string& name) {
  return "op " + std::to_string(index + 1) + (name.empty() ? "" : " (" + name + ")");
}

bool is_pixel_op(const std::string& name) {
  static const std::vector<std::string> kPixelOps = {"lasso", "barrier", "clear",    "seed",
                                                     "grow",  "add",     "subtract", "auto"};
  return std::find(kPixelOps.begin(), kPixelOps.end(), name) != kPixelOps.end();
}

SegmentScript read_segment_script(const std::filesystem::path& path) {
  SegmentScript script;
  script.file = path.string();
  const std::string& file = script.file;
  const nlohmann::json document = acquisition::read_json_file(path, kMaxScriptBytes);
  if (!document.is_object() || !document.contains("ops") || !document["ops"].is_array()) {
    refuse(file, "", "a script is an object with an array \"ops\"");
  }
  acquisition::refuse_unknown_keys(document, {"scan", "ops"}, {file, ""});
  if (document["ops"].size() > kMaxOps) {
    refuse(file, "key \"ops\"",
           "holds " + std::to_string(document["ops"].size()) + " ops, more than " +
               std::to_string(kMaxOps) + ": split the script");
  }
  if (document.contains("scan")) script.scan = read_scan_id(document["scan"], {file, ""});
  for (std::size_t k = 0; k < document["ops"].size(); ++k)
    script.ops.push_back(read_op(document["ops"][k], k, file));
  return script;
}

}  // namespace scanbench::app
