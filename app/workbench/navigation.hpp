// The 3D view's camera: orbit about a target or walk/fly through the scene,
// with speeds fitted to the scene's size.
#pragma once

#include <Eigen/Geometry>

#include "acquisition/camera_view.hpp"

namespace scanbench::app::workbench {

class Navigation {
 public:
  // Frames `box` (world): the target at its centre, the eye back far
  // enough to see all of it, speeds scaled to its diagonal. With `facing`
  // (a direction from the box towards the viewer, not zero) the eye moves
  // to that side, a little above; otherwise the view direction stays.
  void frame(const Eigen::AlignedBox3d& box,
             const Eigen::Vector3d& facing = Eigen::Vector3d::Zero());
  // Orbit: pixels of mouse motion turn the eye about the target.
  void orbit(double dx_px, double dy_px);
  // Moves eye and target across the view by pixels of mouse motion.
  void pan(double dx_px, double dy_px, double view_height_px);
  // Wheel steps: closer (positive) or farther, 15 % a step.
  void zoom(double steps);
  // Walk/fly: moves the eye (and the target with it) along the view
  // direction, to the right and up, at the fitted speed for `seconds`.
  void fly(double forward, double right, double up, double seconds);
  // Turns the view direction about the eye (fly mode's mouse look).
  void look(double dx_px, double dy_px);

  acquisition::CameraView camera(int width, int height) const;
  double speed_m_per_s() const { return speed_; }
  const Eigen::Vector3d& eye() const { return eye_; }
  const Eigen::Vector3d& target() const { return target_; }

 private:
  Eigen::Vector3d forward() const;
  Eigen::Vector3d target_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d eye_ = Eigen::Vector3d(-30.0, 0.0, 15.0);
  double yaw_ = 0.0;      // of the view direction, about +z [rad]
  double pitch_ = -0.45;  // of the view direction above the horizon [rad]
  double distance_ = 33.0;
  double speed_ = 10.0;
  double fov_deg_ = 60.0;
};

}  // namespace scanbench::app::workbench
