// The register and merge stages: align every scan of a project (issue #5)
// and store the poses with a report, then decide the merged model's points
// and store them as keep masks. Each stage is one transaction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

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
  std::vector<std::int64_t> ids;  // scan ids, in the order of the result's scans
  std::vector<std::string> names;
  registration::RegistrationResult result;
  std::string report_json;  // as stored in the project
};

// Registers every scan of the project (the first scan by id is the
// reference and keeps its pose), then in one transaction stores the new
// poses, the report, and drops the now stale merge keep masks. A failed pair
// is reported, and its scan keeps its pose relative to its target. Throws
// core::InputError for a missing, foreign or damaged project, a scan
// without geometry ("run scanbench geometry first"), or picks that do not
// name the project's scans as the settings require; the project is then
// unchanged.
RegisterStageResult register_project(const std::filesystem::path& project_path,
                                     const RegisterStageSettings& settings);

struct MergeStageScan {
  std::int64_t id = 0;
  std::string name;
  registration::MergeScanResult counts;  // keep left empty
};

struct MergeStageResult {
  std::vector<MergeStageScan> scans;
  std::size_t points = 0;
  double seconds = 0.0;  // the merge decision itself
};

// Computes the keep mask of every scan at its stored pose and stores them in
// one transaction, replacing earlier masks. Throws core::InputError
// as register_project does.
MergeStageResult merge_project(const std::filesystem::path& project_path,
                               const registration::MergeSettings& settings);

}  // namespace scanbench::modeling
