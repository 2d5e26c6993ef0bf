// What association needs of a target scan around one source's samples: the
// pixels that the samples fall on at one pose, and their neighbours, with
// the target's range, point, normal, footprint and usable flag there. A
// stage that associates the same pairs again and again at poses that move
// little (the rounds of the global refinement, the report of the links)
// keeps these patches instead of the target scans, which are a hundred
// times larger and take seconds to load. Association through a patch gives
// the same matches as through the whole scan, or says that it cannot (a
// sample fell on a pixel the patch does not hold; association.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

#include "acquisition/spherical_grid.hpp"
#include "registration/prepared_scan.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

// Parallel arrays, one entry per pixel held, in ascending pixel order.
struct TargetPatch {
  std::vector<std::int64_t> pixels;      // row-major pixel of the target scan
  std::vector<float> range_m;            // the scan's range there
  std::vector<Eigen::Vector3f> points;   // as PreparedScan::points
  std::vector<Eigen::Vector3f> normals;  // as ScanGeometry::normal
  std::vector<float> footprint_m;        // as ScanGeometry::footprint_m
  std::vector<std::uint8_t> usable;      // as PreparedScan::usable

  std::size_t size() const { return pixels.size(); }
  // Its arrays, for core::SpillShelf.
  auto vectors() { return std::tie(pixels, range_m, points, normals, footprint_m, usable); }
  auto vectors() const { return std::tie(pixels, range_m, points, normals, footprint_m, usable); }

  // The position of `pixel` in the arrays, or -1 when the patch lacks it.
  std::int64_t slot_of(std::int64_t pixel) const;
};

// The patch of `target` (a spherical grid, asserted) around `source`'s
// samples at T_target_source (source scan frame → target scan frame): every
// pixel within `margin` rows and columns of a pixel a sample falls on
// (columns wrap around). With a margin of one, a later pose may move each
// sample by half a pixel at least before association needs the whole scan.
TargetPatch patch_of(const SampleCloud& source, const PreparedScan& target,
                     const Eigen::Isometry3d& T_target_source, int margin);

// A patch with the grid of its target scan: what association reads.
struct PatchedTarget {
  const acquisition::SphericalGrid& grid;
  const TargetPatch& patch;
};

}  // namespace scanbench::registration
