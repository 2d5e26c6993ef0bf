// Every command's settings and result as JSON, in one place. The journal
// stores them this way and `scanbench history` shows them. The settings of
// the batch commands (geometry, register, merge, harmonize) also read back
// into the command that wrote them: `scanbench history P --settings ID`
// prints a command's settings, and `--settings FILE` runs that command with
// them again.
//
// Settings are whole structs, every field but the thread counts (which
// never change a result). A field added to a struct must be added to
// command_json.cpp (settings; command_result_json.cpp holds the results);
// tests/modeling/test_command_json.cpp finds a field that is read but not
// written.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

namespace scanbench::modeling {

// Compact text with any invalid UTF-8 replaced: how the journal stores JSON.
std::string dump(const nlohmann::json& json);

// Instantiated for the settings of import (ImportSettings; the command adds
// its files), geometry (acquisition::GeometrySettings), register
// (RegisterCommandSettings), merge (registration::MergeSettings), harmonize
// (HarmonizeCommandSettings), select (SelectSettings) and commit
// (CommitSettings), and for their
// parts acquisition::ScanFileSettings and registration::RegistrationSettings.
template <typename Settings>
std::string settings_to_json(const Settings& settings);

// Where settings being read come from, which decides what is refused.
enum class SettingsSource {
  // The journal, written by this or another version of scanbench: missing
  // keys take the struct's defaults and unknown keys are ignored, so older
  // and newer records read.
  kJournal,
  // A file a user gives (`--settings FILE`): a key the struct does not have,
  // a value that does not read back as written (2.7 or 4294967297 for a
  // count) and a value outside the range the command accepts are refused.
  kUser,
};

// Reads the settings in `json`. Throws core::InputError naming `origin`
// (a file, or "command 7") and the key at fault when `json` is not an
// object, a value has the wrong type, or (kUser) the rules above refuse it.
// Instantiated for import, geometry, register, merge, harmonize, select and
// commit.
template <typename Settings>
Settings settings_from_json(const nlohmann::json& json, const std::string& origin,
                            SettingsSource source);
// The same, from text.
template <typename Settings>
Settings settings_from_json(const std::string& json, const std::string& origin,
                            SettingsSource source = SettingsSource::kJournal);

// The result a command stores in the journal and its `--json` prints, one
// JSON object:
// - ImportResult: {"scans": [id]};
// - GeometryCommandResult: {"scans": [{"id", "valid_points", "normals",
//   "mixed_pixels", "edge_pixels"}], "seconds"};
// - RegisterCommandResult: {"pairs": [...], "global", "edges", "overall",
//   "poses": [{"scan", "name", "initial_T_world_scan", "T_world_scan"}]}
//   (docs/registration.md);
// - MergeCommandResult: {"scans": [{"id", "name", "in_model", "kept",
//   "redundant"}], "points", "kept", "seconds"};
// - HarmonizeCommandResult: {"scans": [{"id", "name", "reference", "pairs",
//   "delta_e_before", "delta_e_after", "matrix", "offset"}], "pairs",
//   "delta_e_before", "delta_e_after", "iterations", "converged", "seconds"}.
// The tree and colour commands store small results ({"node": id}) made
// where they are computed.
template <typename Result>
std::string result_json(const Result& result);

}  // namespace scanbench::modeling
