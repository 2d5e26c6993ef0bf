// The harmonize command: one colour correction per scan from the overlaps
// of the registered scans (registration/color_harmonization.hpp), stored as
// the command "harmonize".
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "modeling/store/project.hpp"
#include "registration/color_harmonization.hpp"

namespace scanbench::modeling {

struct HarmonizeCommandSettings {
  registration::ColorPairSettings pairs;
  registration::HarmonizeSettings solve;
};

struct HarmonizeCommandScan {
  std::int64_t id = 0;
  std::string name;
  store::ScanColorCorrection correction;
  // The fixed scan of its group of overlapping scans (itself for that one);
  // none: it overlaps no scan and keeps its correction.
  std::optional<std::int64_t> reference;
  std::size_t pairs = 0;  // colour pairs it takes part in
  // Mean CIE76 ΔE to the other scan of its pairs, before and after.
  double delta_e_before = 0.0;
  double delta_e_after = 0.0;
};

struct HarmonizeCommandResult {
  std::int64_t command_id = 0;
  std::vector<HarmonizeCommandScan> scans;  // by id
  std::size_t pairs = 0;
  double delta_e_before = 0.0;  // mean over every pair
  double delta_e_after = 0.0;
  int iterations = 0;
  bool converged = false;
  double seconds = 0.0;
  double pair_search_seconds = 0.0;  // of seconds: finding the colour pairs
  double solve_seconds = 0.0;        // of seconds: the corrections' solve
};

// Mean CIE76 ΔE between the two colours of each pair, each corrected by its
// scan's correction (by index into `corrections`; empty: none).
double mean_pair_delta_e(std::span<const registration::ColorPair> pairs,
                         std::span<const store::ScanColorCorrection> corrections);

// Harmonises the colours of the project's scans at their current poses
// (seed 004 §4.5; registration/color_harmonization.hpp): colour pairs from
// the overlaps, one correction per scan with the first scan (by id) of each
// group of overlapping scans fixed, stored as one command ("harmonize")
// whose undo restores the earlier corrections. Scans that overlap no other
// keep theirs.
// Streams: colour pairs only between scans whose bounds meet, each scan
// loaded once, one at a time under `memory_limit`, paired with the colour
// samples (registration::ColorSamples) of the earlier scans it may overlap,
// which wait in a temporary file (in memory, within the limit, where no
// such file can take them).
// Throws as merge_project (no scans, a scan without geometry, data it read
// changed meanwhile, a scan beyond the memory limit, cancelled), and
// core::RuntimeFailure when the temporary file cannot be read back, and
// core::InputError when no two scans with colour overlap. The project is
// then unchanged.
HarmonizeCommandResult harmonize_project(store::Project& project,
                                         const HarmonizeCommandSettings& settings,
                                         core::Progress& progress,
                                         std::optional<std::uint64_t> memory_limit = std::nullopt);

}  // namespace scanbench::modeling
