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
//   A grid scan is read, computed and written a band of rows at a time
// (docs/scale.md, "Big scans"): bands of about `band_pixels` pixels, at
// least one tile of the window fits (acquisition::geometry_band_cuts), so
// that memory does not grow with the scan (a band's inputs, scratch and
// results take about 45 bytes a pixel: some 200 MB at the default, where a
// 3600 × 900 station is one band); the result is the whole scan's
// geometry bit for bit, whatever the bands. A cloud (scattered scan) is
// computed whole: its neighbours may lie anywhere in it.
inline constexpr std::size_t kGeometryBandPixels = std::size_t{1} << 22;
GeometryCommandResult geometry_project(store::Project& project,
                                       const acquisition::GeometrySettings& settings,
                                       core::Progress& progress,
                                       std::size_t band_pixels = kGeometryBandPixels);

}  // namespace scanbench::modeling
