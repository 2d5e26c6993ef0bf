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
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "modeling/lod/lod_store.hpp"
#include "modeling/lod/octree_cube.hpp"
#include "modeling/lod/octree_sampling.hpp"
#include "modeling/store/layer_store.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::lod {

struct ShownPointsSettings {
  // The largest stretch of a splat along its major axis (splat_shape.hpp).
  float max_stretch = 64.0f;
  std::size_t band_pixels = std::size_t{1} << 20;  // rows read at a time, in pixels
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
  int band_rows = 1;              // the rows of the bands it was read in
};

// The shown points of scan `stored`, positions only: `visit` gets each band's
// positions in quanta from `cube`'s corner (the cube holds the model,
// relative to `origin` in world metres); an empty `visit` asks for the
// survey alone (no position is computed). Throws core::InputError naming
// the scan when it has no geometry or a layer is damaged, or a point lies
// outside the cube (when positions are computed).
ScanSurvey survey_scan(
    const store::Project& project, const store::StoredScanSummary& stored, const OctreeCube& cube,
    const Eigen::Vector3d& origin, const ShownPointsSettings& settings,
    const std::function<void(std::span<const std::array<std::uint32_t, 3>>)>& visit);

// A band of a scan's rows as the store holds them.
struct ShownBand {
  int first_row = 0, end_row = 0, columns = 0;
  // Per pixel of the band, row-major: its owner as the store's digest
  // holds it (LodStore::owners).
  std::span<const std::uint32_t> owners;
  // Pixel g of the band, an in-model pixel (valid, not mixed), with
  // everything the store keeps of it, offsets from the cube's corner; its
  // object is owners[g].
  std::function<BuildPoint(std::size_t g)> point;
};

// Scan `stored` for the store's scan `scan` (its intensity spread from
// survey_scan), band by band, `scan.digest_rows` rows a band: `visit` gets
// each band in turn. Throws as survey_scan.
void read_shown_bands(const store::Project& project, const store::StoredScanSummary& stored,
                      const LodScan& scan, const OctreeCube& cube, const Eigen::Vector3d& origin,
                      const ShownPointsSettings& settings,
                      const std::function<void(const ShownBand&)>& visit);

// The owner of in-model pixel g as the store's digest holds it, from the
// merge's keep mask and the membership (none: the scan has no such layer).
inline std::uint32_t shown_owner(const std::optional<std::vector<std::uint8_t>>& keep,
                                 const std::optional<std::vector<std::uint32_t>>& membership,
                                 std::size_t g) {
  if (keep && (*keep)[g] == 0) return kNotShown;
  if (!membership) return 0;
  return (*membership)[g] == store::kDeletedPoints ? kNotShown : (*membership)[g];
}

// The layers that say which of a scan's points are shown and whose they
// are, `rows_per_band` rows at a time: `visit(first_row, end_row, keep,
// membership)` for each band (none: the scan has no such layer). Throws
// core::InputError naming the scan and layer when one is damaged.
void read_owner_layers(
    const store::Project& project, const store::StoredScanSummary& stored, int rows_per_band,
    const std::function<void(int, int, const std::optional<std::vector<std::uint8_t>>&,
                             const std::optional<std::vector<std::uint32_t>>&)>& visit);

// What a scan's points in the store were read from: the journal's commands
// that wrote the layers placing and describing a point, and those that
// wrote the layers saying whether it is shown and whose it is (the merge's
// keep mask and the membership). Equal sources: equal points, equal owners.
struct ScanSources {
  std::string points, owners;
};
ScanSources scan_sources(const store::Project& project, std::int64_t scan_id);

// The values of the layers placing and describing a scan's points, as
// fingerprints (Project::layer_fingerprint): equal when a stage run again
// wrote the same values. Reads each layer's end.
std::string scan_points_content(const store::Project& project, std::int64_t scan_id);

}  // namespace scanbench::lod
