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
// as one command (new versions of the "keep" layers). Streams: each scan is
// compared only with the scans whose bounds reach it (scan_overlaps.hpp),
// and at most `memory_limit` bytes of scans are loaded at once (default:
// memory_limit_or_default). Throws core::InputError for a project without
// scans or a scan without geometry, core::MemoryShortage when two scans do
// not fit in the limit, core::Cancelled; nothing is stored then.
MergeCommandResult merge_project(store::Project& project,
                                 const registration::MergeSettings& settings,
                                 core::Progress& progress,
                                 std::optional<std::uint64_t> memory_limit = std::nullopt);

}  // namespace scanbench::modeling
