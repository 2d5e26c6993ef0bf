// An unstructured cloud as a file holds it (LAS, PLY), on its way to
// becoming a scattered scan (scan.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Readers reserve scattered_pixel_count(points) entries (three for rgb), so
// that the scan takes the vectors without copying them.
struct PointCloud {
  std::vector<Eigen::Vector3d> points;  // in the file's frame [m], its order
  std::vector<float> intensity;         // empty, or one per point
  std::vector<std::uint8_t> rgb;        // empty, or R, G, B per point
};

// The scattered scan of `cloud` (its points taken), named after the stem
// of `path`, with `path` as its source file. Throws core::InputError naming
// `path` when the cloud has no point (a 0 × 0 scan is no scan). Asserts the
// channels are empty or one per point.
Scan scattered_scan(PointCloud&& cloud, const std::filesystem::path& path);

}  // namespace scanbench::acquisition
