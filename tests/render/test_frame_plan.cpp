// The frame plan: what is culled by the frustum (through the tree), by
// facing, by level of detail and the budget, and the draw order.
#include <gtest/gtest.h>

#include "render/frame_plan.hpp"
#include "wall_model.hpp"

namespace scanbench::render {
namespace {

using test::kOrigin;

TEST(FramePlan, AWallInFullViewIsDrawnWholeNearestTileFirst) {
  const RenderModel model = test::wall_model();
  ASSERT_GE(model.tiles.size(), 8u);  // 4800 points in tiles of 600
  const RenderView view =
      make_render_view(test::camera_at({1000.0, 2000.0, 1.5}, 640, 480), kOrigin);
  const FramePlan plan = plan_frame(model, view, {});
  EXPECT_EQ(plan.points, 4800u);
  EXPECT_EQ(plan.submitted, 4800u);
  EXPECT_EQ(plan.culled_frustum + plan.culled_backface + plan.culled_budget, 0u);
  EXPECT_EQ(plan.tiles_drawn, model.tiles.size());
  for (std::size_t k = 1; k < plan.draws.size(); ++k)
    EXPECT_LE(plan.draws[k - 1].distance_m, plan.draws[k].distance_m);
}

TEST(FramePlan, BehindTheCameraOrFacingAwayIsCulled) {
  const RenderModel model = test::wall_model();
  // Looking away from the wall: the group's box is outside, all of it culled.
  acquisition::CameraView away = test::camera_at({1000.0, 2000.0, 1.5});
  away.T_world_camera.linear() = -away.T_world_camera.linear().eval();
  away.T_world_camera.linear().col(1) *= -1.0;  // a rotation again
  FramePlan plan = plan_frame(model, make_render_view(away, kOrigin), {});
  EXPECT_EQ(plan.culled_frustum, 4800u);
  EXPECT_TRUE(plan.draws.empty());
  // Behind the wall, looking at its back.
  plan = plan_frame(model, make_render_view(test::camera_at({1020.0, 2000.0, 1.5}), kOrigin), {});
  EXPECT_EQ(plan.culled_backface, 4800u);
  CullSettings off;
  off.backface = false;
  EXPECT_EQ(
      plan_frame(model, make_render_view(test::camera_at({1020.0, 2000.0, 1.5}), kOrigin), off)
          .submitted,
      4800u);
}

// A clipping box or slice away from the wall culls all of it, counted as
// clipped; one across it keeps the tiles it touches; a point's own test
// decides at the box's faces and the slab's.
TEST(FramePlan, TheClippingBoxAndSliceCullWhatLiesOutside) {
  const RenderModel model = test::wall_model();
  const RenderView view =
      make_render_view(test::camera_at({1000.0, 2000.0, 1.5}, 640, 480), kOrigin);
  CullSettings away;
  away.clipping.box = Eigen::AlignedBox3f(Eigen::Vector3f(20, -5, -5), Eigen::Vector3f(30, 5, 5));
  FramePlan plan = plan_frame(model, view, away);
  EXPECT_EQ(plan.culled_clip, 4800u);
  EXPECT_TRUE(plan.draws.empty());
  CullSettings slice;
  slice.clipping.section_offset = 10.0f;  // z = 10 m, far above the 3 m wall
  slice.clipping.section_half_width = 0.5f;
  EXPECT_EQ(plan_frame(model, view, slice).culled_clip, 4800u);
  CullSettings across;
  across.clipping.box = Eigen::AlignedBox3f(Eigen::Vector3f(9, 0, -1), Eigen::Vector3f(11, 3, 4));
  plan = plan_frame(model, view, across);
  EXPECT_GT(plan.culled_clip, 0u);
  EXPECT_LT(plan.culled_clip, 4800u);
  EXPECT_EQ(plan.culled_clip + plan.submitted, 4800u);
  EXPECT_TRUE(across.clipping.keeps({10.0f, 1.0f, 1.0f}));
  EXPECT_FALSE(across.clipping.keeps({10.0f, -1.0f, 1.0f}));
  slice.clipping.section_offset = 1.5f;
  EXPECT_TRUE(slice.clipping.keeps({10.0f, 0.0f, 1.9f}));
  EXPECT_FALSE(slice.clipping.keeps({10.0f, 0.0f, 2.1f}));
}

TEST(FramePlan, HiddenObjectsAreSkippedAndCounted) {
  const RenderModel model = test::wall_model(true);
  const FramePlan plan =
      plan_frame(model, make_render_view(test::camera_at({1000.0, 2000.0, 1.5}), kOrigin), {});
  EXPECT_EQ(plan.hidden, 2400u);
  EXPECT_EQ(plan.submitted, 2400u);
}

TEST(FramePlan, FarAwayTilesAreThinnedAndTheBudgetHolds) {
  const RenderModel model = test::wall_model();
  // From 1 km, 5 cm is a twentieth of a pixel: each tile shrinks to a prefix
  // whose cells are about a pixel, and its splats grow to close it.
  const RenderView far = make_render_view(test::camera_at({0.0, 2000.0, 1.5}, 640, 480), kOrigin);
  const FramePlan thinned = plan_frame(model, far, {});
  EXPECT_LT(thinned.submitted, 4800u / 4);
  EXPECT_EQ(thinned.submitted + thinned.culled_budget, 4800u);
  for (const TileDraw& draw : thinned.draws) EXPECT_GT(draw.min_radius_m, 0.05f);
  CullSettings budget;
  budget.level_of_detail = false;
  budget.budget = 1000;
  const FramePlan cut = plan_frame(
      model, make_render_view(test::camera_at({1000.0, 2000.0, 1.5}, 640, 480), kOrigin), budget);
  EXPECT_LE(cut.submitted, 1000u);
  EXPECT_GT(cut.submitted, 950u);
  EXPECT_EQ(cut.culled_budget, 4800u - cut.submitted);
}

}  // namespace
}  // namespace scanbench::render
