// The frame budget follows the device: on a simulated device whose frames
// cost a fixed part and a part per point, moving frames settle at the
// target within a few frames, after a slowdown too; a still camera has no
// budget, and a view that needs few points does not inflate it.
#include <gtest/gtest.h>

#include "render/frame_budget.hpp"

namespace scanbench::render {
namespace {

// A frame of `points` on a device drawing `per_ms` points a millisecond.
double simulated_frame_ms(std::size_t points, double per_ms) {
  return 15.0 + static_cast<double>(points) / per_ms;
}

TEST(FrameBudget, MovingFramesSettleAtTheTargetAndFollowASlowdown) {
  FrameBudget budget(100.0);
  EXPECT_EQ(budget.next(false), 0u);  // still: full quality
  double per_ms = 10000.0;
  double last_ms = 0.0;
  for (int frame = 0; frame < 40; ++frame) {
    if (frame == 20) per_ms = 2500.0;  // the view got harder (larger splats)
    const std::size_t points = budget.next(true);
    last_ms = simulated_frame_ms(points, per_ms);
    budget.record(last_ms, points);
    if (frame == 12 || frame == 32) {
      EXPECT_NEAR(last_ms, 100.0, 10.0) << frame;
    }
  }
  EXPECT_NEAR(last_ms, 100.0, 5.0);
  EXPECT_NEAR(static_cast<double>(budget.next(true)), 85.0 * 2500.0, 0.1 * 85.0 * 2500.0);
}

TEST(FrameBudget, AViewNeedingFewPointsDoesNotInflateIt) {
  FrameBudget budget(100.0);
  for (int frame = 0; frame < 20; ++frame) budget.record(20.0, 30000);  // fast, wanted no more
  EXPECT_LE(budget.next(true), 60000u);
  for (int frame = 0; frame < 20; ++frame) budget.record(1000.0, 30000);  // a very slow device
  EXPECT_EQ(budget.next(true), FrameBudget::kFewestPoints);
}

}  // namespace
}  // namespace scanbench::render
