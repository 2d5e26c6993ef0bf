// The geometry stage: footprints, normals and mixed-pixel flags for every
// scan of a project, stored in it (seed 004 §4.2).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "acquisition/scan_geometry.hpp"

namespace scanbench::modeling {

struct GeometryStageSettings {
  acquisition::GeometrySettings geometry;
  // Called after each scan's geometry is stored (inside the transaction). Optional.
  std::function<void(std::size_t done, std::size_t total, const std::string& scan_name)>
      on_scan_done;
};

struct GeometryStageScan {
  std::int64_t id = 0;
  std::string name;
  std::size_t valid_points = 0;
  std::size_t normals = 0;
  std::size_t mixed_pixels = 0;
  std::size_t edge_pixels = 0;
  double seconds = 0.0;
};

struct GeometryStageResult {
  std::vector<GeometryStageScan> scans;
  double seconds = 0.0;
};

// Computes and stores the geometry of every scan of the project, replacing
// earlier results, in one transaction: on any error nothing is stored.
// Throws core::InputError for a missing, foreign or damaged project.
GeometryStageResult compute_project_geometry(const std::filesystem::path& project_path,
                                             const GeometryStageSettings& settings = {});

// The settings as the JSON text stored beside the results (without
// `threads`: the results do not depend on it).
std::string geometry_settings_json(const acquisition::GeometrySettings& settings);

}  // namespace scanbench::modeling
