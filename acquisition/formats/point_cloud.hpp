// An unstructured cloud as a file holds it (LAS, PLY), on its way to
// becoming a scattered scan (scan.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "acquisition/scan.hpp"
#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// Readers reserve scattered_pixel_count(points) entries (three for rgb), so
// that the scan takes the vectors without copying them.
struct PointCloud {
  std::vector<Eigen::Vector3d> points;  // in the file's frame [m], its order
  std::vector<float> intensity;         // empty, or one per point
  std::vector<std::uint8_t> rgb;        // empty, or R, G, B per point
  // Recorded geometry (RecordedGeometry): empty, or one per point. Normals
  // in the file's frame, of any length (zero or not finite: none);
  // footprints as a radius [m] (not positive or not finite: none).
  std::vector<Eigen::Vector3f> normal;
  std::vector<float> footprint_m;
};

// The scattered scan of `cloud` (its points taken), named after the stem
// of `path`, with `path` as its source file, and the geometry the cloud
// recorded, its normals turned into the scan frame and made unit length.
// Throws core::InputError naming `path` when the cloud has no point (a
// 0 × 0 scan is no scan). Asserts the channels are empty or one per point.
// The caller fills the rest of the source.
ImportedScan scattered_scan(PointCloud&& cloud, const std::filesystem::path& path);

}  // namespace scanbench::acquisition
