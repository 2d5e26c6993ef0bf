// The merge command: decide the merged model's points (registration/
// merge.hpp: each point kept only where no other scan sampled its surface
// more finely) and store them as keep masks, as the command "merge".
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "modeling/store/project.hpp"
#include "registration/merge.hpp"

namespace scanbench::modeling {

struct MergeCommandScan {
  std::int64_t id = 0;
  std::string name;
  registration::MergeScanResult counts;  // keep left empty
};

struct MergeCommandResult {
  std::int64_t command_id = 0;  // the journal entry
  std::vector<MergeCommandScan> scans;
  std::size_t points = 0;
  double seconds = 0.0;  // the merge decision itself
};

// Computes the keep mask of every scan at its current pose and stores them
// as one command (new versions of the "keep" layers). Throws as
// register_project does.
MergeCommandResult merge_project(store::Project& project,
                                 const registration::MergeSettings& settings,
                                 core::Progress& progress);

}  // namespace scanbench::modeling
