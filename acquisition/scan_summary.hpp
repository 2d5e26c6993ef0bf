// What `scanbench info` shows of a scan without loading its channels: sizes,
// channel presence, pose and world bounds. The project stores one per scan.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <string>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

struct ScanSummary {
  std::string name;
  int rows = 0;
  int columns = 0;
  std::size_t valid_points = 0;
  bool has_color = false;
  bool has_intensity = false;
  bool spherical = true;  // angle model: spherical, else per-pixel directions
  bool scattered = false;  // an unstructured cloud (PerPixelDirections::scattered)
  Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();
  std::optional<Eigen::AlignedBox3d> bbox_world;  // empty when no valid point
  ScannerMetadata scanner;
};

// One pass over the scan (the bounds need every valid point).
ScanSummary summarize(const Scan& scan);

// "spherical" or "per_pixel", the names used in JSON and in the project.
const char* angle_model_name(bool spherical);

}  // namespace scanbench::acquisition
