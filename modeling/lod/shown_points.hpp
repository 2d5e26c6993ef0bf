// The points of a project's shown model, as the level-of-detail store holds
// them (docs/lod.md): each scan's in-model points (valid, not mixed pixels)
// that the merge kept, where it ran, and the segmentation did not delete.
// Hidden objects' points are in it: hiding is the renderer's business. A
// scan is read from the project a band of rows at a time
// (modeling/scan_rows.hpp), so a scan larger than memory passes too.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "modeling/lod/lod_store.hpp"
#include "modeling/lod/octree_cube.hpp"
#include "modeling/lod/octree_sampling.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::lod {

struct ShownPointsSettings {
  // The largest stretch of a splat along its major axis (splat_shape.hpp).
  float max_stretch = 64.0f;
  std::size_t band_pixels = std::size_t{1} << 22;  // rows read at a time, in pixels
};

// Throws core::InputError naming the project and scan `stored` ("scan ID
// (NAME)"), with `problem`.
[[noreturn]] void refuse_scan(const store::Project& project, const store::StoredScanSummary& stored,
                              const std::string& problem);

// What a first pass over a scan finds.
struct ScanSurvey {
  // The 2nd and 98th percentiles of its in-model intensities (within 1/4096
  // of their value), or 0 and 1 without intensity.
  float intensity_low = 0.0f;
  float intensity_high = 1.0f;
  std::uint64_t in_model = 0;     // its in-model points
  std::uint64_t merged_away = 0;  // of those, dropped by the merge's keep mask
  std::uint64_t deleted = 0;      // marked deleted by the segmentation
  std::uint64_t shown = 0;        // the rest: the points the store holds
};

// The shown points of scan `stored`, positions only: `visit` gets each band's
// positions in quanta from `cube`'s corner (the cube holds the model,
// relative to `origin` in world metres). Throws core::InputError naming the
// scan when it has no geometry or a layer is damaged, or a point lies
// outside the cube.
ScanSurvey survey_scan(
    const store::Project& project, const store::StoredScanSummary& stored, const OctreeCube& cube,
    const Eigen::Vector3d& origin, const ShownPointsSettings& settings,
    const std::function<void(std::span<const std::array<std::uint32_t, 3>>)>& visit);

// The same points with everything the store keeps of them, for the scan
// `scan` describes (its intensity spread from survey_scan): `visit` gets a
// band's points at a time, in the order of their pixels. Throws as
// survey_scan.
void read_shown_points(const store::Project& project, const store::StoredScanSummary& stored,
                       const LodScan& scan, const OctreeCube& cube, const Eigen::Vector3d& origin,
                       const ShownPointsSettings& settings,
                       const std::function<void(std::span<const BuildPoint>)>& visit);

}  // namespace scanbench::lod
