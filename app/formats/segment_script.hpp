// `scanbench segment PROJECT --script OPS.json`: a segment script
// (segment_script_file.hpp) played on a project.
//
// The whole file is checked before anything runs. The script is one unit
// (Project::Batch): an op refused while it runs (a node that is not there,
// an empty selection), a write error or a cancel stops it and rolls back
// every op before it, undos and redos included, so a refused script leaves
// the project, journal and redo chain, as it found it; core::InputError
// names the file and the op. The project's write lock is held while the
// script runs.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "app/formats/segment_script_file.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::app {

struct SegmentScriptResult {
  // One entry per op: {"op", "command" (its journal id, or null), "result"}.
  nlohmann::json ops = nlohmann::json::array();
  // The command keeping the selections the script left uncommitted in the
  // project (they are the next script's and the workbench's to go on
  // with); 0 when none changed, or when keeping them would have ended the
  // redo chain (the script ended on an undo): then `selections_held_back`.
  std::int64_t kept_selections = 0;
  bool selections_held_back = false;
};

// Plays `script` (read_segment_script) on `project`.
SegmentScriptResult run_segment_script(store::Project& project, const SegmentScript& script);

// Reads the file at `script`, then plays it.
SegmentScriptResult run_segment_script(store::Project& project,
                                       const std::filesystem::path& script);

}  // namespace scanbench::app
