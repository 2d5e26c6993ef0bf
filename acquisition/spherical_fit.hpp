// Recovering the panoramic angle model from a grid of measured points.
//
// PTX files store points, not angles. When the grid was sampled at regular
// azimuth and elevation steps (every panoramic scanner, and our virtual one),
// the points are explained by four numbers; storing those instead of a
// direction per pixel makes the scan's structure usable as an index (projective
// association in registration, footprints from the angular step).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

struct SphericalFitSettings {
  // The grid counts as regular when replacing every valid point's direction by
  // the model's moves no point by more than this [m]. 0.05 mm is far below
  // the noise of any terrestrial scanner and far above the rounding of
  // 6-decimal text; with the float range it keeps every point within 0.1 mm
  // of the file's value (local_origin.hpp).
  double max_deviation_m = 5e-5;
};

struct SphericalFitResult {
  bool regular = false;        // true when `angles` explains every valid point
  SphericalAngles angles;      // meaningful when regular
  double max_deviation_m = 0;  // largest point displacement under the model [m]
  std::size_t points_used = 0;
};

// Fits azimuth = start + col · step and elevation = start + row · step to the
// valid points of a rows × columns grid (row-major, scan frame, z up) by least
// squares, after unwrapping azimuths around a robust (median) step estimate.
// Returns regular = false when fewer than two valid points exist or any point
// deviates by more than settings.max_deviation_m; the caller then keeps
// per-pixel directions. Asserts the spans hold rows × columns entries.
SphericalFitResult fit_spherical_angles(int rows, int columns,
                                        std::span<const Eigen::Vector3d> points_scan,
                                        std::span<const std::uint8_t> valid,
                                        const SphericalFitSettings& settings = {});

// The same fit for a grid whose directions are given as angles (E57's
// spherical coordinates): azimuth and elevation [rad] and range [m] per pixel,
// row-major, read where `valid`. The deviation of a point is its range times
// the angle between its direction and the model's (to first order), so no
// point is recomputed. Asserts the spans hold rows × columns entries.
SphericalFitResult fit_spherical_angles_to_angles(int rows, int columns,
                                                  std::span<const double> azimuth,
                                                  std::span<const double> elevation,
                                                  std::span<const float> range,
                                                  std::span<const std::uint8_t> valid,
                                                  const SphericalFitSettings& settings = {});

}  // namespace scanbench::acquisition
