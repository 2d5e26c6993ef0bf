#include "app/workbench/navigation.hpp"

#include <algorithm>
#include <cmath>

namespace scanbench::app::workbench {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kRadiansPerPixel = 0.006;
constexpr double kMaxPitch = 1.45;  // short of straight up or down
}  // namespace

Eigen::Vector3d Navigation::forward() const {
  return {std::cos(pitch_) * std::cos(yaw_), std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_)};
}

void Navigation::frame(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& facing) {
  if (box.isEmpty()) return;
  if (facing.norm() > 0.0) {
    // Look against `facing`, from a little above it.
    const Eigen::Vector3d look = -facing.normalized();
    yaw_ = std::atan2(look.y(), look.x());
    pitch_ = std::clamp(std::asin(std::clamp(look.z(), -1.0, 1.0)) - 0.25, -kMaxPitch, kMaxPitch);
    if (std::hypot(look.x(), look.y()) < 1e-3) yaw_ = 0.0;  // straight down or up
  }
  const double diagonal = std::max(box.diagonal().norm(), 1.0);
  target_ = box.center();
  distance_ = 0.5 * diagonal / std::tan(0.5 * fov_deg_ * kPi / 180.0) * 1.1;
  eye_ = target_ - distance_ * forward();
  speed_ = std::max(diagonal / 8.0, 0.5);
}

void Navigation::orbit(double dx_px, double dy_px) {
  yaw_ -= dx_px * kRadiansPerPixel;
  pitch_ = std::clamp(pitch_ + dy_px * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
  eye_ = target_ - distance_ * forward();
}

void Navigation::pan(double dx_px, double dy_px, double view_height_px) {
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d right = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = right.cross(f);
  const double metres_per_pixel =
      2.0 * distance_ * std::tan(0.5 * fov_deg_ * kPi / 180.0) / std::max(view_height_px, 1.0);
  const Eigen::Vector3d shift = metres_per_pixel * (-dx_px * right + dy_px * up);
  target_ += shift;
  eye_ += shift;
}

void Navigation::zoom(double steps) {
  distance_ = std::clamp(distance_ * std::pow(0.85, steps), 0.5, 1e5);
  eye_ = target_ - distance_ * forward();
}

void Navigation::fly(double forward_amount, double right_amount, double up_amount, double seconds) {
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d right = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d shift =
      speed_ * seconds *
      (forward_amount * f + right_amount * right + up_amount * Eigen::Vector3d::UnitZ());
  eye_ += shift;
  target_ += shift;
}

void Navigation::look(double dx_px, double dy_px) {
  yaw_ -= dx_px * kRadiansPerPixel;
  pitch_ = std::clamp(pitch_ - dy_px * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
  target_ = eye_ + distance_ * forward();
}

acquisition::CameraView Navigation::camera(int width, int height) const {
  acquisition::CameraView view;
  view.width = width;
  view.height = height;
  view.vertical_fov_deg = fov_deg_;
  view.T_world_camera = acquisition::look_at(eye_, eye_ + forward());
  return view;
}

}  // namespace scanbench::app::workbench
