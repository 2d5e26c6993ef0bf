// The register and merge stages: align every scan of a project and store
// the poses with a report (the command "register"), then decide the merged
// model's points and store them as keep masks (the command "merge").
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "modeling/project.hpp"
#include "registration/color_harmonization.hpp"
#include "registration/merge.hpp"
#include "registration/register_scans.hpp"

namespace scanbench::modeling {

// Picked point pairs between two scans of the project, named by id.
struct ProjectPicks {
  std::int64_t source_id = 0;
  std::int64_t target_id = 0;
  std::vector<registration::PointPair> pairs;  // each point in its own scan frame [m]
};

struct RegisterStageSettings {
  registration::RegistrationSettings registration;
  // For CoarseMethod::kPointPairs: for every scan but the first (in id
  // order), one entry with that scan as source and an earlier scan as target.
  std::vector<ProjectPicks> picks;
};

struct RegisterStageResult {
  std::int64_t command_id = 0;    // the journal entry
  std::vector<std::int64_t> ids;  // scan ids, in the order of the result's scans
  std::vector<std::string> names;
  registration::RegistrationResult result;
  std::string report_json;  // as stored in the journal (the command's result)
};

// Registers every scan of the project (the first scan by id is the
// reference and keeps its pose), then as one command stores the new poses
// (earlier poses stay in the history), the report as the command's result,
// and removes the now stale merge keep masks. A failed pair is reported, and
// its scan keeps its pose relative to its target. Throws core::InputError
// for a damaged project, a project without scans, a scan without geometry
// ("run scanbench geometry first"), or picks that do not name the project's scans as the settings
// require; core::RuntimeFailure when another process changed the project
// meanwhile; core::Cancelled when cancelled. The project is then unchanged.
RegisterStageResult register_project(Project& project, const RegisterStageSettings& settings,
                                     core::Progress& progress);

struct MergeStageScan {
  std::int64_t id = 0;
  std::string name;
  registration::MergeScanResult counts;  // keep left empty
};

struct MergeStageResult {
  std::int64_t command_id = 0;  // the journal entry
  std::vector<MergeStageScan> scans;
  std::size_t points = 0;
  double seconds = 0.0;  // the merge decision itself
};

// Computes the keep mask of every scan at its current pose and stores them
// as one command (new versions of the "keep" layers). Throws as
// register_project does.
MergeStageResult merge_project(Project& project, const registration::MergeSettings& settings,
                               core::Progress& progress);

// The merge's result as the JSON object the journal keeps and `scanbench
// merge --json` prints: {"scans":[{"id","name","in_model","kept","redundant"}],
// "points","kept","seconds"}.
std::string merge_result_json(const MergeStageResult& result);

struct HarmonizeStageSettings {
  registration::ColorPairSettings pairs;
  registration::HarmonizeSettings solve;
};

struct HarmonizeStageScan {
  std::int64_t id = 0;
  std::string name;
  ScanColorCorrection correction;
  // The fixed scan of its group of overlapping scans (itself for that one);
  // none: it overlaps no scan and keeps its correction.
  std::optional<std::int64_t> reference;
  std::size_t pairs = 0;  // colour pairs it takes part in
  // Mean CIE76 ΔE to the other scan of its pairs, before and after.
  double delta_e_before = 0.0;
  double delta_e_after = 0.0;
};

struct HarmonizeStageResult {
  std::int64_t command_id = 0;
  std::vector<HarmonizeStageScan> scans;  // by id
  std::size_t pairs = 0;
  double delta_e_before = 0.0;  // mean over every pair
  double delta_e_after = 0.0;
  int iterations = 0;
  bool converged = false;
  double seconds = 0.0;
};

// Mean CIE76 ΔE between the two colours of each pair, each corrected by its
// scan's correction (by index into `corrections`; empty: none).
double mean_pair_delta_e(std::span<const registration::ColorPair> pairs,
                         std::span<const ScanColorCorrection> corrections);

// Harmonises the colours of the project's scans at their current poses
// (seed 004 §4.5; registration/color_harmonization.hpp): colour pairs from
// the overlaps, one correction per scan with the first scan (by id) of each
// group of overlapping scans fixed, stored as one command ("harmonize")
// whose undo restores the earlier corrections. Scans that overlap no other
// keep theirs.
// Throws as merge_project (no scans, a scan without geometry, a project
// changed meanwhile, cancelled), and core::InputError when no two scans
// with colour overlap. The project is then unchanged.
HarmonizeStageResult harmonize_project(Project& project, const HarmonizeStageSettings& settings,
                                       core::Progress& progress);

std::string harmonize_result_json(const HarmonizeStageResult& result);

}  // namespace scanbench::modeling
