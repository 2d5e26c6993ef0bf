// A spatially even subsample of a scan's usable points, with their normals:
// the source side of ICP and the input of the feature-based coarse stage.
// Scanner clouds are dense near the scanner and sparse far away; an even
// sample keeps the near ground from outvoting the rest of the scene.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

#include "registration/prepared_scan.hpp"

namespace scanbench::registration {

// Parallel arrays, one entry per sample, in the scan frame.
struct SampleCloud {
  std::vector<Eigen::Vector3f> points;   // [m]
  std::vector<Eigen::Vector3f> normals;  // unit, pointing to the scanner
  std::vector<std::int64_t> pixels;      // row-major pixel of the scan
  std::size_t size() const { return points.size(); }
  // Its arrays, for core::SpillShelf.
  auto vectors() { return std::tie(points, normals, pixels); }
  auto vectors() const { return std::tie(points, normals, pixels); }
};

struct SampleSettings {
  double voxel_m = 0.2;            // at most one sample per cube of this edge
  std::size_t max_points = 40000;  // then thinned evenly to at most this many
};

// The first usable pixel (in row-major order) of every occupied voxel, then
// every k-th of those when there are more than max_points. Deterministic.
// Asserts voxel_m > 0 and max_points > 0.
SampleCloud sample_scan(const PreparedScan& scan, const SampleSettings& settings);

// Every k-th sample of `cloud`, with the smallest k that leaves at most
// max_points (asserted > 0). Deterministic.
SampleCloud thin(const SampleCloud& cloud, std::size_t max_points);

}  // namespace scanbench::registration
