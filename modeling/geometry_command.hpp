// The geometry stage: footprints, normals and mixed-pixel flags for every
// scan of a project (seed 004 §4.2), stored as the command "geometry".
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "core/progress.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::modeling {

struct GeometryCommandScan {
  std::int64_t id = 0;
  std::string name;
  std::size_t valid_points = 0;
  std::size_t normals = 0;
  std::size_t recorded_normals = 0;  // of them, as the scan's file recorded them
  std::size_t mixed_pixels = 0;
  std::size_t edge_pixels = 0;
  // The σ(range) the depth-jump and mixed-pixel tests used: estimated from
  // the scan (GeometrySettings::estimate_range_noise) or the settings'.
  acquisition::RangeNoise range_noise;
  bool noise_estimated = false;
  double seconds = 0.0;
};

struct GeometryCommandResult {
  std::int64_t command_id = 0;  // the journal entry
  std::vector<GeometryCommandScan> scans;
  double seconds = 0.0;
};

// Computes the geometry of every scan of `project` and stores it as one
// command, with the settings in the journal: new versions of the four
// geometry layers of every scan, and the merge's keep masks removed (they
// were decided on the old geometry). Written scan by scan
// (Project::LongCommand), one unit of `progress` each. Nothing becomes
// visible on any error or when cancelled (core::Cancelled). Throws
// core::InputError when the project has no scans, core::RuntimeFailure when
// another process changed its scans meanwhile.
GeometryCommandResult geometry_project(store::Project& project,
                                       const acquisition::GeometrySettings& settings,
                                       core::Progress& progress);

}  // namespace scanbench::modeling
