// Labels carried from one registered scan to another: each point of the
// target scan takes the label of the source pixel that sampled the same
// surface. The point is carried into the source's frame and associated with
// a source pixel (projectively on a spherical grid), then the merge's
// same-surface test decides (prepared_scan.hpp: range within the noise and
// the footprint, normals within an angle). This is how an object drawn in
// one scan covers the surface in every scan that saw it.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "acquisition/range_noise.hpp"
#include "registration/prepared_scan.hpp"

namespace scanbench::registration {

struct LabelTransferSettings {
  // One σ(range) model for both scans; none: each scan's own (its
  // geometry's range_noise).
  std::optional<acquisition::RangeNoise> noise;
  double range_sigmas = 4.0;  // as MergeSettings
  double max_normal_angle_deg = 30.0;
  int threads = 0;  // 0 = all cores; results do not depend on it
};

// How a target point appears from the source scan, on the source pixel
// whose beam it lies on.
enum class Sighting : std::uint8_t {
  // The source did not sample this place: no pixel there (outside its grid,
  // or not in the model), or its range there is shorter (a nearer surface
  // hides the point) or longer (its beam passed the point's place).
  kUnseen,
  // The source pixel sampled this place (the range agrees) but on another
  // surface: the normals disagree.
  kPlace,
  // The source pixel sampled the same surface (same_surface()).
  kSurface,
};

// Per target pixel, row-major: the source pixel its point lies on (-1 where
// none, or the target pixel is not in the model) and what that pixel saw.
struct Sightings {
  std::vector<std::int32_t> pixel;  // 5 bytes a pixel with the sighting
  std::vector<Sighting> sighting;
};

// What `source` saw of every point of `target`. T_source_target maps the
// target's scan frame into the source's.
Sightings sight_in_source(const PreparedScan& source, const PreparedScan& target,
                          const Eigen::Isometry3d& T_source_target,
                          const LabelTransferSettings& settings);

// For every pixel of `target`, row-major: the label of the pixel of
// `source` whose surface it samples (Sighting::kSurface), 0 where there is
// none or the source pixel's label is 0. `labels` has one entry per source
// pixel (asserted).
std::vector<std::uint32_t> transfer_labels(const PreparedScan& source,
                                           std::span<const std::uint32_t> labels,
                                           const PreparedScan& target,
                                           const Eigen::Isometry3d& T_source_target,
                                           const LabelTransferSettings& settings);

}  // namespace scanbench::registration
