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
#include <span>
#include <vector>

#include "acquisition/range_noise.hpp"
#include "registration/prepared_scan.hpp"

namespace scanbench::registration {

struct LabelTransferSettings {
  acquisition::RangeNoise noise;  // the scanner's
  double range_sigmas = 4.0;      // as MergeSettings
  double max_normal_angle_deg = 30.0;
  int threads = 0;  // 0 = all cores; results do not depend on it
};

// For every pixel of `target`, row-major: the label of the pixel of
// `source` whose surface it samples, 0 where there is none (the target
// pixel is not in the model, falls outside the source's grid or on another
// surface, or the source pixel's label is 0). `labels` has one entry per
// source pixel (asserted). T_source_target maps the target's scan frame
// into the source's.
std::vector<std::uint32_t> transfer_labels(const PreparedScan& source,
                                           std::span<const std::uint32_t> labels,
                                           const PreparedScan& target,
                                           const Eigen::Isometry3d& T_source_target,
                                           const LabelTransferSettings& settings);

}  // namespace scanbench::registration
