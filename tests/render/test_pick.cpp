// Picking in the 3D view (render/pick): the ray through a pixel meets the
// point the view draws there, and nothing the view does not draw.
#include <gtest/gtest.h>

#include "render/pick.hpp"
#include "wall_model.hpp"

namespace scanbench::render {
namespace {

using test::kOrigin;

RenderView front_view() {
  return make_render_view(test::camera_at({1000.0, 2000.0, 1.5}, 640, 480), kOrigin);
}

// The picture's centre is the wall's centre (10, 0, 1.5) in the model's
// frame; a sample lies every 5 cm, so the point picked is within a
// sample's half diagonal (3.6 cm) of where the ray meets the wall.
TEST(Pick, TheRayThroughAPixelMeetsThePointDrawnThere) {
  const RenderModel model = test::wall_model();
  const RenderView view = front_view();
  const std::optional<Pick> centre =
      pick_point(model, view.eye, pixel_ray(view, 320.0, 240.0), {}, 1.5f);
  ASSERT_TRUE(centre.has_value());
  EXPECT_LT((centre->position - Eigen::Vector3f(10.0f, 0.0f, 1.5f)).norm(), 0.036f);
  EXPECT_NEAR(centre->distance_m, 10.0f, 0.05f);
  // Left of the centre on screen is +y (the red half, object 1).
  const std::optional<Pick> left =
      pick_point(model, view.eye, pixel_ray(view, 200.0, 240.0), {}, 1.5f);
  ASSERT_TRUE(left.has_value());
  EXPECT_GT(left->position.y(), 0.3f);
  EXPECT_EQ(model.points.node[left->point], 1u);
  // Above the wall there is nothing.
  EXPECT_FALSE(pick_point(model, view.eye, pixel_ray(view, 320.0, 20.0), {}, 1.5f).has_value());
}

// A ray meets a splat where the view draws it: the long thin splat of the
// ground under the ray, whose 4 m major radius reaches the ray 1.5 m above
// it, does not catch it; the wall behind does. Aimed at the strip, the ray
// meets it.
TEST(Pick, ALongGroundSplatCatchesOnlyTheRaysThatMeetIt) {
  const RenderModel model = test::wall_model(false, true);
  const RenderView view = front_view();
  const std::optional<Pick> centre =
      pick_point(model, view.eye, pixel_ray(view, 320.0, 240.0), {}, 1.5f);
  ASSERT_TRUE(centre.has_value());
  EXPECT_NE(model.points.node[centre->point], 0u);
  EXPECT_NEAR(centre->distance_m, 10.0f, 0.05f);
  const Eigen::Vector3f eye(0.0f, 0.0f, 1.5f);
  const Eigen::Vector3f to_strip = (Eigen::Vector3f(7.0f, 0.01f, 0.0f) - eye).normalized();
  const std::optional<Pick> strip = pick_point(model, eye, to_strip, {}, 1.5f);
  ASSERT_TRUE(strip.has_value());
  EXPECT_EQ(model.points.node[strip->point], 0u);
  EXPECT_NEAR(strip->distance_m, (Eigen::Vector3f(7.0f, 0.01f, 0.0f) - eye).norm(), 1e-3f);
}

TEST(Pick, HiddenClippedAndBackFacingPointsAreNotPicked) {
  const RenderView view = front_view();
  const Eigen::Vector3f right_ray = pixel_ray(view, 440.0, 240.0);
  EXPECT_TRUE(pick_point(test::wall_model(), view.eye, right_ray, {}, 1.5f).has_value());
  EXPECT_FALSE(pick_point(test::wall_model(true), view.eye, right_ray, {}, 1.5f).has_value());
  Clipping left_only;
  left_only.box = Eigen::AlignedBox3f(Eigen::Vector3f(9, 0, -1), Eigen::Vector3f(11, 3, 4));
  EXPECT_FALSE(pick_point(test::wall_model(), view.eye, right_ray, left_only, 1.5f).has_value());
  // From behind, the wall faces away.
  const Eigen::Vector3f behind(20.0f, 0.0f, 1.5f);
  EXPECT_FALSE(pick_point(test::wall_model(), behind, Eigen::Vector3f(-1.0f, 0.0f, 0.0f), {}, 1.5f)
                   .has_value());
}

}  // namespace
}  // namespace scanbench::render
