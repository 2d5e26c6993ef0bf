// Closed-form rigid alignment of point pairs: the coarse registration from
// three or more points that the user picked in two scans.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <span>

namespace scanbench::registration {

// One picked correspondence: the same physical point seen in two frames [m].
struct PointPair {
  Eigen::Vector3d source = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
};

struct RigidFitResult {
  // False when there are fewer than 3 pairs or the source points are (nearly)
  // collinear, so that a rotation about their line is undetermined. The
  // other fields are then meaningless.
  bool valid = false;
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  double rms_m = 0.0;           // RMS of |T · source − target| over the pairs
  double max_residual_m = 0.0;  // largest |T · source − target|
  std::size_t pairs = 0;
};

// Least-squares rigid transform (rotation and translation, no scale) taking
// every pair's source point onto its target point: the SVD solution of Arun,
// Huang and Blostein (1987), with Umeyama's (1991) sign correction so that
// the result is a rotation, never a reflection. Exact for noise-free pairs.
RigidFitResult fit_rigid(std::span<const PointPair> pairs);

}  // namespace scanbench::registration
