// The segment script file (`scanbench segment PROJECT --script OPS.json`):
// the segmentation's commands (modeling/selection_commands.hpp, tree_commands.hpp) as ops, the same
// the workbench issues; segment_script.hpp plays them. The file:
//
//   {"scan": 1,                                   default scan (default: the first)
//    "ops": [
//      {"op": "lasso", "points": [[x, y], ...]},  limits the next grows (≥ 3 points)
//      {"op": "barrier", "points": [[x, y], ...]},  stops them (≥ 1 point)
//      {"op": "clear"},                           no lasso, no barriers
//      {"op": "seed", "at": [x, y]},             the click; grows below may omit "seed"
//      {"op": "grow", "seed": [x, y], "channel": "normal", "tolerance": 6},
//      {"op": "add", ...}, {"op": "subtract", ...}, as grow, on the selection
//      {"op": "commit", "name": "wall", "parent": NODE},
//      {"op": "group", "name": "north hall", "parent": NODE, "children": [NODE, ...]},
//      {"op": "rename", "node": NODE, "name": "..."},
//      {"op": "hide", "node": NODE}, {"op": "show", "node": NODE},
//      {"op": "reparent", "node": NODE, "parent": NODE or null},
//      {"op": "delete", "node": NODE, "points": "pool" or "deleted"},
//      {"op": "ungroup", "node": NODE},           its children move up
//      {"op": "merge", "nodes": [NODE, …]},       objects into the first
//      {"op": "separate", "node": NODE},          an object's parts in the scan
//      {"op": "auto", "group": "proposals", "parent": NODE,
//       "channel": "normal", "tolerance": 6, "min_pixels": 200},
//      {"op": "undo"}, {"op": "redo"}]}
//
// Image coordinates: x = column, y = row of the scan's grid (constraints.hpp).
// "scan" may be given on any op. NODE is a node id, or the name of exactly
// one live node. "channel" is range, color, intensity or normal (default
// normal); "tolerance" defaults to the channel's (region_grow.hpp).
//
// Grows (grow, add, subtract) change the selection, session state: no
// command. "undo" takes back the script's grows since its last command
// first, then commands; a selection the script leaves uncommitted is kept
// in the project at its end (SelectionTools::keep).
//
//
// At most 16 MB and 10 000 ops; unknown ops and keys (at the top and in an
// op) are refused, not ignored.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "modeling/selection_commands.hpp"
#include "segmentation/constraints.hpp"
#include "segmentation/proposals.hpp"
#include "segmentation/region_grow.hpp"

namespace scanbench::app {

// One op of the file, checked and typed.
struct ScriptOp {
  std::string name;
  std::optional<std::int64_t> scan;
  segmentation::Polyline points;                   // lasso, barrier
  Eigen::Vector2d seed = Eigen::Vector2d::Zero();  // seed, grow, add, subtract
  bool has_seed = true;  // grow, add, subtract: false = the last seed op's
  segmentation::GrowSettings grow;
  std::string text;                      // commit, group, rename: the name
  nlohmann::json node;                   // a NODE reference
  std::optional<nlohmann::json> parent;  // given: a NODE or null
  std::vector<nlohmann::json> children;  // group; merge: the objects
  modeling::DeletedPoints deleted_points = modeling::DeletedPoints::kToPool;  // delete
  std::size_t min_pixels = segmentation::ProposalSettings{}.min_pixels;       // auto
};

struct SegmentScript {
  std::string file;                  // as given, for messages
  std::optional<std::int64_t> scan;  // the default scan
  std::vector<ScriptOp> ops;
};

// Reads and checks the whole file. Throws core::InputError naming the file,
// the op ("op 3 (grow)") or key, and the problem; core::RuntimeFailure when
// it cannot be read.
SegmentScript read_segment_script(const std::filesystem::path& file);

// "op 3 (grow)": where op `index` (from 0) of a script is.
std::string script_op_place(std::size_t index, const std::string& name);

// Ops on pixels and the tools (lasso, barrier, clear, seed, grow, add,
// subtract, auto); the others are on the tree or the journal.
bool is_pixel_op(const std::string& name);

}  // namespace scanbench::app
