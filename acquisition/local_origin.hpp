// A scan's grid from points given in a file's frame, with a local origin
// that keeps every coordinate to 0.1 mm at any magnitude, checked point by
// point (LocalOriginResult::max_error_m; out of reach only for clouds
// spread over more than 900 m around their centroid).
//
// Ranges and per-pixel directions are floats. Measured from the world's
// origin, a float range of a point near (637012, 8490281, 431) is off by up
// to 0.5 m. So a scan's frame (the origin of T_world_scan) sits near its
// points: at the centre of projection when the grid is a panorama around it,
// else near the points themselves, and the offset goes into T_world_scan in
// double precision.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>

#include "acquisition/scan.hpp"
#include "acquisition/spherical_fit.hpp"

namespace scanbench::acquisition {

struct LocalOriginSettings {
  // When the grid is regular around a candidate centre within this
  // tolerance the scan gets the spherical angle model (spherical_fit.hpp).
  SphericalFitSettings angle_fit;
  // Per-pixel directions stay measured from the file's own origin while no
  // point is farther than this [m] from it. A float range and a float unit
  // direction put a point within 1.1e-7 × its range of its value: 0.055 mm
  // at 500 m. Beyond, the origin moves to the points' centroid.
  double max_per_pixel_range_m = 500.0;
  // Every representation is checked point by point: a point may come back
  // this far from its file value [m] at most, or the next one is tried.
  double max_error_m = 1e-4;
  // False: per-pixel directions even for a regular grid (depth cameras).
  bool try_spherical = true;
};

struct LocalOriginResult {
  Eigen::Vector3d origin_file = Eigen::Vector3d::Zero();  // the new scan frame's origin [m]
  bool spherical = false;
  // The largest range from the origin [m].
  double farthest_m = 0.0;
  // The largest distance of a point from its file value after the round
  // trip [m], or a bound of it when the bound is within max_error_m (the
  // points are then not checked one by one). Within max_error_m unless even
  // per-pixel directions from the centroid cannot keep it: points spread
  // over more than about 900 m around it, where float ranges and directions
  // err by about 1.1e-7 × range.
  double max_error_m = 0.0;
};

// Sets scan.range_m, scan.angles and scan.T_world_scan of `scan`, whose
// rows, columns and valid mask are set and whose T_world_scan is the file's
// pose of `points_file` (rows × columns, row-major, the file's scan frame
// [m]; only valid pixels are read). Candidate centres of projection are the
// file frame's origin, then `centre_hint_file` (a scanner position the file
// records, in the file's scan frame): the first around which the grid is a
// regular panorama and every point comes back within max_error_m wins, the
// scan frame moves there, and the scan is spherical. Otherwise the scan
// keeps per-pixel directions measured from the file frame's origin, when no
// point lies farther than max_per_pixel_range_m from it and every point
// comes back, or else from the centroid of the valid points (rounded to
// 1 m). T_world_scan becomes pose · translation(origin). Asserts the spans
// hold rows × columns entries.
LocalOriginResult set_grid_from_points(Scan& scan, std::span<const Eigen::Vector3d> points_file,
                                       const std::optional<Eigen::Vector3d>& centre_hint_file,
                                       const LocalOriginSettings& settings = {});

// The same for a scattered scan (make_scattered_scan), whose k-th valid
// pixel takes points_file[k]: per-pixel directions from the file frame's
// origin, or from the points' centroid when they lie far from it. Asserts
// one point per valid pixel. The points are taken (moved in, they are not
// copied) and padded to the grid: a reader that reserves
// scattered_pixel_count(n) spares a reallocation.
LocalOriginResult set_scattered_points(Scan& scan, std::vector<Eigen::Vector3d> points_file);

}  // namespace scanbench::acquisition
