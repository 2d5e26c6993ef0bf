#include "render/frame_budget.hpp"

#include <algorithm>
#include <cassert>

namespace scanbench::render {

FrameBudget::FrameBudget(double target_ms, std::size_t first_budget)
    : target_ms_(target_ms), budget_(std::max(first_budget, kFewestPoints)) {
  assert(target_ms > 0.0 && "a frame-time target must be positive");
}

void FrameBudget::record(double frame_ms, std::size_t points) {
  if (!(frame_ms > 0.0)) return;
  const double factor = std::clamp(target_ms_ / frame_ms, 0.5, 1.5);
  double next = factor * static_cast<double>(budget_);
  if (points < budget_) next = std::min(next, 2.0 * static_cast<double>(points));
  budget_ = std::max(kFewestPoints, static_cast<std::size_t>(next));
}

}  // namespace scanbench::render
