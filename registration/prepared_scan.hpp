// A scan made ready for registration and merging: its points in its own
// frame, which of them a model may use, how much surface each one samples,
// and an index that associates any point with one of its pixels.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"
#include "acquisition/spherical_grid.hpp"
#include "registration/point_index.hpp"

namespace scanbench::registration {

// Per-pixel arrays, rows × columns, row-major like the scan.
struct PreparedScan {
  // Not owned: scan and geometry must outlive the PreparedScan.
  const acquisition::Scan* scan = nullptr;
  const acquisition::ScanGeometry* geometry = nullptr;
  // Point in the scan frame [m]; zero where the pixel is not in the model.
  // A spherical grid's may be dropped (empty) where only the merge uses the
  // scan: it recomputes them from the ranges (registration/merge.hpp).
  std::vector<Eigen::Vector3f> points;
  // 1 = the point belongs in a model: valid and not a mixed pixel.
  std::vector<std::uint8_t> in_model;
  // 1 = in the model and with a valid normal: usable for plane residuals.
  std::vector<std::uint8_t> usable;
  // Surface area [m²] that the sample stands for: range² · the pixel's solid
  // angle / |cos incidence| (incidence clamped at 87°; head-on where the
  // normal is invalid). The inverse of the local sampling rate: the Jacobian
  // determinant of the map between two range images is a ratio of these.
  std::vector<float> sample_area_m2;
  // Association: a spherical grid projects, other grids use the kd-tree.
  std::optional<acquisition::SphericalGrid> grid;
  std::unique_ptr<PointIndex> tree;
};

// Whether prepare_scan computes the points of a spherical grid (other
// grids need them for their index).
enum class GridPoints { kComputed, kLeftOut };

// Builds the arrays and the index for `scan` with its `geometry` (same pixel
// count; asserted). `threads` workers, 0 = all cores; the result does not
// depend on it.
PreparedScan prepare_scan(const acquisition::Scan& scan, const acquisition::ScanGeometry& geometry,
                          int threads, GridPoints grid_points = GridPoints::kComputed);

// The pixel of `target` associated with `p_target` (a point in the target's
// scan frame [m]): for spherical grids the pixel on whose beam it lies
// (projective association, O(1)), otherwise the nearest usable point. -1 when
// there is none. The pixel may be unusable; callers check.
std::int64_t associate(const PreparedScan& target, const Eigen::Vector3f& p_target);

// The σ(range) of `scan`'s measurements: `one_for_all` when given (a model
// the user set for every scan), else the scan's own (ScanGeometry::
// range_noise, estimated by the geometry stage).
inline const acquisition::RangeNoise& range_noise_of(
    const PreparedScan& scan, const std::optional<acquisition::RangeNoise>& one_for_all) {
  return one_for_all ? *one_for_all : scan.geometry->range_noise;
}

// The same-surface test of seed 004 §4.3, shared by the merge and the
// transfer of labels: pixel k of scan o sampled the surface of a point p of
// another scan when o's range there agrees with p's range from o, range_p,
// within range_sigmas · sigma (the two measurements' combined noise) plus
// o's footprint at k (the beam centre and p may be a pixel apart on a
// slanted surface), and, where both have a normal, the normals agree
// within acos(min_normal_cos). normal_p is p's normal in its own scan's
// frame (nullptr: none), R_o_p the rotation from that frame into o's.
inline bool same_surface(const PreparedScan& o, std::size_t k, float range_p, float sigma,
                         const Eigen::Vector3f* normal_p, const Eigen::Matrix3f& R_o_p,
                         float range_sigmas, float min_normal_cos) {
  if (!o.in_model[k]) return false;
  const float tolerance = range_sigmas * sigma + o.geometry->footprint_m[k];
  if (std::abs(o.scan->range_m[k] - range_p) > tolerance) return false;
  if (normal_p == nullptr || !o.usable[k]) return true;
  return (R_o_p * *normal_p).dot(o.geometry->normal[k]) >= min_normal_cos;
}

}  // namespace scanbench::registration
