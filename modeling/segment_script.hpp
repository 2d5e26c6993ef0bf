// `scanbench segment PROJECT --script OPS.json`: the segmentation's
// commands (segment_commands.hpp) played from a file, the same commands the
// workbench issues. The file:
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
// The whole file is checked before anything runs. An op refused while the
// script runs (a node that is not there, an empty selection) stops it, and
// the commands it made are undone, so a refused script leaves the project
// as it found it; core::InputError names the file and the op.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "modeling/project.hpp"

namespace scanbench::modeling {

struct SegmentScriptResult {
  // One entry per op: {"op", "command" (its journal id, or null), "result"}.
  nlohmann::json ops = nlohmann::json::array();
};

SegmentScriptResult run_segment_script(Project& project, const std::filesystem::path& script);

}  // namespace scanbench::modeling
