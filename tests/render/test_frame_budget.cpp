// The frame budget follows the device: on a simulated device whose frames
// cost a fixed part and a part per point, moving frames settle at the
// target within a few frames, after a slowdown too; a still camera has no
// budget, and a view that needs few points does not inflate it. On one
// whose frames cost pixels, moving frames are drawn smaller.
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
      EXPECT_NEAR(last_ms, 85.0, 10.0) << frame;
    }
  }
  // Frames aim at 85 % of the target, so that most meet it.
  EXPECT_NEAR(last_ms, 85.0, 5.0);
  EXPECT_NEAR(static_cast<double>(budget.next(true)), 70.0 * 2500.0, 0.1 * 70.0 * 2500.0);
}

TEST(FrameBudget, AViewNeedingFewPointsDoesNotInflateIt) {
  FrameBudget budget(100.0);
  for (int frame = 0; frame < 20; ++frame) budget.record(20.0, 30000);  // fast, wanted no more
  EXPECT_LE(budget.next(true), 60000u);
  for (int frame = 0; frame < 20; ++frame) budget.record(1000.0, 30000);  // a very slow device
  EXPECT_EQ(budget.next(true), FrameBudget::kFewestPoints);
}

// A device that spends a frame filling pixels (llvmpipe with large
// splats): fewer points do not help, so once the budget is down to its
// fewest, moving frames are drawn smaller until they meet the target; an
// easier view gives the resolution back before the points.
TEST(FrameBudget, FramesFilledByPixelsAreDrawnSmaller) {
  FrameBudget budget(100.0);
  double fill_ms = 240.0;  // the whole picture's pixels
  const auto frame_ms = [&](std::size_t points, double scale) {
    return 10.0 + fill_ms * scale * scale + static_cast<double>(points) / 50000.0;
  };
  EXPECT_EQ(budget.scale(false), 1.0);
  double last_ms = 0.0;
  for (int frame = 0; frame < 40; ++frame) {
    const std::size_t points = budget.next(true);
    last_ms = frame_ms(points, budget.scale(true));
    budget.record(last_ms, points);
  }
  EXPECT_EQ(budget.next(true), FrameBudget::kFewestPoints);
  EXPECT_NEAR(last_ms, 85.0, 15.0);
  EXPECT_LT(budget.scale(true), 0.75);
  EXPECT_GE(budget.scale(true), FrameBudget::kSmallestScale);
  EXPECT_EQ(budget.scale(false), 1.0);  // still: the whole picture
  fill_ms = 40.0;                       // an easier view
  for (int frame = 0; frame < 40; ++frame) {
    const std::size_t points = budget.next(true);
    budget.record(frame_ms(points, budget.scale(true)), points);
  }
  EXPECT_EQ(budget.scale(true), 1.0);
  EXPECT_GT(budget.next(true), FrameBudget::kFewestPoints);
}

}  // namespace
}  // namespace scanbench::render
