// A rigid pose as Ceres parameter blocks: a unit quaternion (Eigen's x, y, z,
// w order, on ceres::EigenQuaternionManifold) and a translation [m]. The
// SO(3) × R³ parametrisation of the Ceres pose-graph example: updates stay on
// the rotation manifold, and no Euler-angle singularity exists.
#pragma once

#include <Eigen/Geometry>
#include <utility>

namespace scanbench::registration {

struct PoseParameters {
  double rotation[4] = {0.0, 0.0, 0.0, 1.0};  // x, y, z, w
  double translation[3] = {0.0, 0.0, 0.0};

  static PoseParameters from(const Eigen::Isometry3d& T) {
    PoseParameters pose;
    const Eigen::Quaterniond q(T.linear());
    pose.rotation[0] = q.x();
    pose.rotation[1] = q.y();
    pose.rotation[2] = q.z();
    pose.rotation[3] = q.w();
    for (int i = 0; i < 3; ++i) pose.translation[i] = T.translation()[i];
    return pose;
  }

  Eigen::Isometry3d isometry() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(rotation[3], rotation[0], rotation[1], rotation[2])
                     .normalized()
                     .toRotationMatrix();
    T.translation() = Eigen::Vector3d(translation[0], translation[1], translation[2]);
    return T;
  }
};

// The rotation angle [rad] and translation length [m] of A⁻¹ · B: how far
// apart two poses are.
inline std::pair<double, double> pose_change(const Eigen::Isometry3d& A,
                                             const Eigen::Isometry3d& B) {
  const Eigen::Isometry3d delta = A.inverse() * B;
  return {Eigen::AngleAxisd(delta.linear()).angle(), delta.translation().norm()};
}

}  // namespace scanbench::registration
