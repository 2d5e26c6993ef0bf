// PCL's normal estimators as the peers of our grid normals (bench "geometry").
// The only place in bench/ that includes PCL headers: this interface speaks
// in scans and Eigen vectors, so PCL's types and compile flags stay in
// pcl_normals.cpp.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "acquisition/scan.hpp"

namespace scanbench::bench {

enum class PclNormalMethod {
  kIntegralCovariance,         // IntegralImageNormalEstimation, COVARIANCE_MATRIX
  kIntegralAverage3dGradient,  // IntegralImageNormalEstimation, AVERAGE_3D_GRADIENT
  kKnnOmp,                     // NormalEstimationOMP on a kd-tree of the valid points
};

struct PclNormalSettings {
  PclNormalMethod method = PclNormalMethod::kIntegralCovariance;
  // Integral image: depth-change threshold factor (PCL multiplies it by the
  // point's z, which PCL takes as the depth of a camera looking along +z).
  float max_depth_change_factor = 0.02f;
  // Integral image: side of the smoothing window [pixels]. PCL shrinks it,
  // per pixel, to the distance [pixels] to the nearest depth change or
  // invalid pixel, and gives no normal within this many pixels of the border.
  float normal_smoothing_size = 10.0f;
  // Integral image: grow the window with z (meant for depth cameras).
  bool depth_dependent_smoothing = false;
  // kNN: neighbours of the PCA fit.
  int k_neighbours = 16;
  // kNN: OpenMP threads. The integral-image estimator has no threading.
  int threads = 2;
  // Timed runs of the estimator; the best is reported (≥ 1).
  int repeats = 1;
};

struct PclNormalResult {
  // Per pixel, row-major like the scan: unit normal in the scan frame, facing
  // the scanner at the origin; the zero vector where PCL gave none (invalid
  // pixel, image border, NaN output).
  std::vector<Eigen::Vector3f> normal;
  std::size_t normals = 0;  // pixels given a normal
  // Best wall time [s] of the estimator alone: for the integral image
  // setInputCloud + compute (its integral images are built there), for kNN
  // the kd-tree build + compute. Building the PCL clouds is not timed.
  double seconds = 0.0;
};

// Runs the PCL estimator on the organized cloud of `scan` (width = columns,
// height = rows, points in the scan frame, NaN where !valid, sensor at the
// origin). Asserts the scan is spherical or per-pixel and consistent, and
// settings.repeats ≥ 1.
PclNormalResult estimate_pcl_normals(const acquisition::Scan& scan,
                                     const PclNormalSettings& settings);

}  // namespace scanbench::bench
