// A level-of-detail store of points held in memory (a test's scene, a
// synthetic model): the same file `scanbench lod` writes, from points given
// in world terms instead of a project's scans.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "modeling/lod/lod_store.hpp"

namespace scanbench::lod {

struct PointToStore {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();    // [m, world]
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();      // unit; zero: unknown
  Eigen::Vector3f major_axis = Eigen::Vector3f::Zero();  // unit; zero: round
  Eigen::Vector2f radii_m = Eigen::Vector2f::Zero();     // across, along the major axis
  std::optional<std::array<std::uint8_t, 3>> rgb;        // none: grey from intensity
  float intensity = 0.5f;                                // [0, 1]
  std::uint32_t object = 0;
  std::uint16_t scan = 0;  // an index into the store's scans
  std::uint32_t pixel = 0;
};

// Writes the store of `points` to `file` (replacing it whole, as a build
// does): positions relative to `origin`, `scans` naming the scan indices
// the points use. Asserts every point's scan is among `scans`.
void write_lod_store(const std::filesystem::path& file, const Eigen::Vector3d& origin,
                     const std::vector<LodScan>& scans, const std::vector<PointToStore>& points,
                     const OctreeSettings& settings = {});

}  // namespace scanbench::lod
