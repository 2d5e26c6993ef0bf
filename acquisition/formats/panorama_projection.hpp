// Gives an unstructured point cloud (E57 data3D without row and column
// indices) the panoramic grid every later stage works on: each point goes
// to the pixel of its azimuth and elevation seen from the scan's origin, at
// an angular step estimated from the points themselves.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace scanbench::acquisition {

struct PanoramaProjection {
  int rows = 0;
  int columns = 0;
  double step_rad = 0.0;  // the angular step of the grid
  // Pixel of each point (row-major), -1 for the points that fell on a pixel
  // a nearer point holds: they are the collisions.
  std::vector<std::int64_t> pixel;
  std::uint64_t collisions = 0;
};

// Projects `points` (the scan's frame [m]) around the origin, or around
// their centroid rounded to 1 m when some lie farther than 500 m from it
// (the local origin's rule, local_origin.hpp). The step is the median
// distance between neighbouring points in the (azimuth, elevation) plane:
// the step of a scan sampled on a regular grid, which then lands on the
// grid's pixels one point each. Azimuths start after the widest gap with
// no point, so that a partial panorama is not split at ±180°. The grid
// holds at most about 4 pixels per point (rounding adds a pixel to each
// side), and fewer than 2^30.
PanoramaProjection project_to_panorama(std::span<const Eigen::Vector3d> points);

}  // namespace scanbench::acquisition
