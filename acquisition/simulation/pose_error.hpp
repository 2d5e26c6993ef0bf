// Seeded pose errors: what registration starts from in benches, tests and
// simulated campaigns whose files carry inexact poses.
#pragma once

#include <Eigen/Geometry>
#include <numbers>

#include "acquisition/simulation/random.hpp"

namespace scanbench::acquisition::sim {

// A rigid error of a uniformly random axis and direction, a rotation angle
// uniform in [0, max_rotation_deg] and a translation length uniform in
// [0, max_translation_m]: E = (R about the pose's origin, then t).
inline Eigen::Isometry3d random_pose_error(double max_rotation_deg, double max_translation_m,
                                           Random& random) {
  const auto unit_vector = [&random] {
    const double z = random.uniform(-1.0, 1.0);
    const double azimuth = random.uniform(0.0, 2.0 * std::numbers::pi);
    const double horizontal = std::sqrt(1.0 - z * z);
    return Eigen::Vector3d(horizontal * std::cos(azimuth), horizontal * std::sin(azimuth), z);
  };
  const double angle_rad = random.uniform(0.0, max_rotation_deg) * std::numbers::pi / 180.0;
  Eigen::Isometry3d error = Eigen::Isometry3d::Identity();
  error.linear() = Eigen::AngleAxisd(angle_rad, unit_vector()).toRotationMatrix();
  const Eigen::Vector3d direction = unit_vector();  // drawn first (random.hpp)
  error.translation() = random.uniform(0.0, max_translation_m) * direction;
  return error;
}

}  // namespace scanbench::acquisition::sim
