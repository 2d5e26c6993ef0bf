// The register command: align every scan of a project (registration/
// register_scans.hpp) and store the poses with a report, as the command
// "register".
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "modeling/store/project.hpp"
#include "registration/register_scans.hpp"

namespace scanbench::modeling {

// Picked point pairs between two scans of the project, named by id.
struct ProjectPicks {
  std::int64_t source_id = 0;
  std::int64_t target_id = 0;
  std::vector<registration::PointPair> pairs;  // each point in its own scan frame [m]
};

struct RegisterCommandSettings {
  registration::RegistrationSettings registration;
  // For CoarseMethod::kPointPairs: for every scan but the first (in id
  // order), one entry with that scan as source and an earlier scan as target.
  std::vector<ProjectPicks> picks;
};

struct RegisterCommandResult {
  std::int64_t command_id = 0;    // the journal entry
  std::vector<std::int64_t> ids;  // scan ids, in the order of the result's scans
  std::vector<std::string> names;
  std::vector<Eigen::Isometry3d> initial_T_world_scan;  // the poses it started from
  registration::RegistrationResult result;
  // The objects' points carried from other scans, carried again at the new
  // poses (carried_objects.hpp): those that went back to the pool, and
  // those carried now.
  std::size_t object_points_released = 0;
  std::size_t object_points_carried = 0;
};

// Registers every scan of the project (the first scan by id is the
// reference and keeps its pose), then as one command stores the new poses
// (earlier poses stay in the history), the report as the command's result,
// removes the now stale merge keep masks, and carries the objects again at
// the new poses (a scan imported after they were drawn gets them then). A failed pair is reported,
// and its scan keeps its pose relative to its target. Throws core::InputError for a damaged
// project, a project without scans, a scan without geometry
// ("run scanbench geometry first"), or picks that do not name the project's scans as the settings
// require; core::RuntimeFailure when another process changed data it read
// meanwhile; core::MemoryShortage when the scans it needs together exceed
// `memory_limit` (default: memory_limit_or_default of scan_cache.hpp);
// core::Cancelled when cancelled. The project is then unchanged. Streams:
// scans are loaded a few at a time (registration::register_scans).
RegisterCommandResult register_project(store::Project& project,
                                       const RegisterCommandSettings& settings,
                                       core::Progress& progress,
                                       std::optional<std::uint64_t> memory_limit = std::nullopt);

}  // namespace scanbench::modeling
