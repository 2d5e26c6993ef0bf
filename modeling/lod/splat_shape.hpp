// The splat of a scan's sample (docs/rendering.md, "Splat shape"): an
// ellipse in the sample's tangent plane covering its share of the surface.
// Seen at incidence θ, a sample's cell stretches by 1 / cos θ along the
// beam's trace on the surface (the major axis) and not across it, capped at
// the geometry stage's limit of 4; beyond it only on ground seen from above
// whose neighbouring samples lie on its tangent plane, and never past them,
// up to max_stretch: far grazing ground needs long splats to close the gaps
// between the scan's rows, while a beam grazing a post, a lamp's head or a
// wall's edge is on a silhouette, where 1 / cos θ throws spears.
//
// Works on a band of a scan's rows (modeling/scan_rows.hpp) as on a whole
// scan: the held rows start at grid row `first_row`, and a pixel's
// neighbours must be held where the grid has them (a row of context on
// either side of the band).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::lod {

struct Splat {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();      // world frame; zero: unknown
  Eigen::Vector2f radii_m = Eigen::Vector2f::Zero();     // across, along the major axis [m]
  Eigen::Vector3f major_axis = Eigen::Vector3f::Zero();  // world frame, unit; zero: round
};

class ScanSplats {
 public:
  // `description`: the scan's grid size, angle model and pose (its arrays
  // are not read; a copy without them is kept). max_stretch: the largest
  // stretch along the major axis.
  ScanSplats(const acquisition::Scan& description, float max_stretch);

  // The unit direction of pixel (row, col) of `held` (rows from grid row
  // `first_row`) in the scan frame, as acquisition::direction_precise gives it.
  Eigen::Vector3d direction(const acquisition::Scan& held, int first_row, int row, int col) const;

  // The splat of pixel (row, col) of `held`, whose normal and footprint
  // are geometry's at index `g`. The pixel must be in the model.
  Splat splat(const acquisition::Scan& held, int first_row,
              const acquisition::ScanGeometry& geometry, std::size_t g, int row, int col) const;

 private:
  std::optional<float> sample_reach(const acquisition::Scan& held, int first_row,
                                    const Eigen::Vector3f& normal, int row, int col,
                                    float reach) const;

  acquisition::Scan description_;  // without its arrays
  float max_stretch_;
  std::optional<acquisition::SphericalDirections> spherical_;
  Eigen::Matrix3f rotation_;  // scan frame → world
  Eigen::Vector3f up_;        // the world's up in the scan frame
  bool wraps_ = false;
  // Per grid row, half the diagonal of its cell [rad]: a sample's footprint
  // per metre of range seen head on. Empty for per-pixel grids (no cell).
  std::vector<float> half_cell_rad_;
};

}  // namespace scanbench::lod
