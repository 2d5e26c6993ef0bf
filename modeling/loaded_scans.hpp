// The scans a command works on, loaded with their geometry: in id order,
// each with its prepared view (registration/prepared_scan.hpp). Internal to
// modeling/; the scale work replaces it with a bounded cache of scans.
#pragma once

#include <cstdint>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"
#include "core/progress.hpp"
#include "modeling/store/project.hpp"
#include "registration/prepared_scan.hpp"

namespace scanbench::modeling {

// Scans with their geometry, in id order, and the prepared views of both.
struct LoadedScans {
  std::vector<std::int64_t> ids;
  std::vector<acquisition::Scan> scans;
  std::vector<acquisition::ScanGeometry> geometry;
  std::vector<registration::PreparedScan> prepared;
};

// Every scan of `project` with its geometry, prepared on `threads` workers
// (one unit of `progress` a scan, under `stage`). Throws core::InputError
// for a project without scans or a scan without geometry ("run scanbench
// geometry first"); core::Cancelled when cancelled.
LoadedScans load_scans(const store::Project& project, int threads, const char* stage,
                       core::Progress& progress);

}  // namespace scanbench::modeling
