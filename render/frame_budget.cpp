#include "render/frame_budget.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace scanbench::render {

FrameBudget::FrameBudget(double target_ms, std::size_t first_budget)
    : target_ms_(target_ms), budget_(std::max(first_budget, kFewestPoints)) {
  assert(target_ms > 0.0 && "a frame-time target must be positive");
}

double FrameBudget::scale(bool moving) const {
  return moving ? std::ceil(scale_ * 16.0 - 1e-9) / 16.0 : 1.0;
}

void FrameBudget::record(double frame_ms, std::size_t points) {
  if (!(frame_ms > 0.0)) return;
  const double factor = std::clamp(kAim * target_ms_ / frame_ms, 0.5, 1.5);
  // The pixels a frame fills go as the square of its scale.
  const bool slow = factor < 1.0;
  if ((slow && budget_ == kFewestPoints) || (!slow && scale_ < 1.0)) {
    scale_ = std::clamp(scale_ * std::sqrt(factor), kSmallestScale, 1.0);
    return;
  }
  double next = factor * static_cast<double>(budget_);
  if (points < budget_) next = std::min(next, 2.0 * static_cast<double>(points));
  budget_ = std::max(kFewestPoints, static_cast<std::size_t>(next));
}

acquisition::CameraView at_scale(const acquisition::CameraView& camera, double scale) {
  acquisition::CameraView out = camera;
  out.width = std::max(16, static_cast<int>(std::lround(scale * camera.width)));
  out.height = std::max(16, static_cast<int>(std::lround(scale * camera.height)));
  return out;
}

}  // namespace scanbench::render
