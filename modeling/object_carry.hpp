// An object drawn in one scan, carried into another registered scan. The
// target's points on the surfaces the drawn scan segmented join the object
// (registration/label_transfer.hpp). Then, where the drawn scan never saw
// the surface (the back of a car, the far side of a crown, the top of a
// low wall seen from below), the object grows on in the target scan from
// those points, on the channel it was drawn with. Growth is bounded twice:
// it never enters a place the drawn scan sampled and left out of the
// object (its decision stands wherever it could make one), and it stays
// within the object's world box, widened by a margin.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <span>

#include "registration/label_transfer.hpp"
#include "registration/prepared_scan.hpp"
#include "segmentation/pixel_set.hpp"
#include "segmentation/region_grow.hpp"
#include "segmentation/segmentation_grid.hpp"

namespace scanbench::modeling {

struct CarrySettings {
  registration::LabelTransferSettings transfer;
  // How the object grows in the target scan; none: it takes only the points
  // on the surfaces the drawn scan segmented.
  std::optional<segmentation::GrowSettings> grow;
  // The growth's box: the object's axis-aligned box in the drawn scan's
  // frame, widened on every side by this fraction of its largest extent.
  double box_margin = 0.25;
};

// The drawn side: the scan the object was drawn in, its pose, and one label
// per pixel (non-zero: in the object).
struct DrawnObject {
  const registration::PreparedScan* scan = nullptr;
  Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();
  std::span<const std::uint32_t> labels;
};

// The scan the object is carried into. `grid` is needed only with
// CarrySettings::grow; without one (a scattered scan, which has no grid)
// the object takes the carried points and does not grow. `open` has one
// byte per pixel: 0 where the pixel may not join (another object's, or
// deleted).
struct CarryTarget {
  const registration::PreparedScan* scan = nullptr;
  Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();
  const segmentation::SegmentationGrid* grid = nullptr;
  std::span<const std::uint8_t> open;
};

// The target's pixels in the object, ascending.
segmentation::PixelSet carry_object(const DrawnObject& drawn, const CarryTarget& target,
                                    const CarrySettings& settings);

}  // namespace scanbench::modeling
