// Picking in the 3D view (LodRenderer::pick): the ray through a pixel meets
// the point the view draws there, and nothing the view does not draw.
#include <gtest/gtest.h>

#include "render/lod_renderer.hpp"
#include "render/pick.hpp"
#include "shared_device.hpp"
#include "wall_model.hpp"

namespace scanbench::render {
namespace {

using test::kOrigin;

RenderView front_view() {
  return make_render_view(test::camera_at({1000.0, 2000.0, 1.5}, 640, 480), kOrigin);
}

// The wall's store with its objects, `hide_right` hiding object 2.
std::unique_ptr<LodRenderer> wall(bool ground_strip = false, bool hide_right = false) {
  test::shared_device();
  auto renderer =
      std::make_unique<LodRenderer>(test::wall_store(ground_strip), LodRendererLimits{});
  renderer->set_objects(test::wall_tree(hide_right));
  return renderer;
}

// The picture's centre is the wall's centre (10, 0, 1.5) in the model's
// frame; a sample lies every 5 cm, so the point picked is within a
// sample's half diagonal (3.6 cm) of where the ray meets the wall.
TEST(Pick, TheRayThroughAPixelMeetsThePointDrawnThere) {
  const std::unique_ptr<LodRenderer> renderer = wall();
  const RenderView view = front_view();
  const std::optional<LodPick> centre = renderer->pick(view.eye, pixel_ray(view, 320.0, 240.0), {});
  ASSERT_TRUE(centre.has_value());
  EXPECT_LT((centre->position - Eigen::Vector3f(10.0f, 0.0f, 1.5f)).norm(), 0.036f);
  EXPECT_NEAR(centre->distance_m, 10.0f, 0.05f);
  // Left of the centre on screen is +y (the red half, object 1).
  const std::optional<LodPick> left = renderer->pick(view.eye, pixel_ray(view, 200.0, 240.0), {});
  ASSERT_TRUE(left.has_value());
  EXPECT_GT(left->position.y(), 0.3f);
  EXPECT_EQ(left->object, 1);
  EXPECT_EQ(left->point.object, 1u);
  // Above the wall there is nothing.
  EXPECT_FALSE(renderer->pick(view.eye, pixel_ray(view, 320.0, 20.0), {}).has_value());
}

// A ray meets a splat where the view draws it: the long thin splat of the
// ground under the ray, whose 4 m major radius reaches the ray 1.5 m above
// it, does not catch it; the wall behind does. Aimed at the strip, the ray
// meets it.
TEST(Pick, ALongGroundSplatCatchesOnlyTheRaysThatMeetIt) {
  const std::unique_ptr<LodRenderer> renderer = wall(true);
  const RenderView view = front_view();
  const std::optional<LodPick> centre = renderer->pick(view.eye, pixel_ray(view, 320.0, 240.0), {});
  ASSERT_TRUE(centre.has_value());
  EXPECT_NE(centre->object, 0);
  EXPECT_NEAR(centre->distance_m, 10.0f, 0.05f);
  const Eigen::Vector3f eye(0.0f, 0.0f, 1.5f);
  const Eigen::Vector3f to_strip = (Eigen::Vector3f(7.0f, 0.01f, 0.0f) - eye).normalized();
  const std::optional<LodPick> strip = renderer->pick(eye, to_strip, {});
  ASSERT_TRUE(strip.has_value());
  EXPECT_EQ(strip->object, 0);
  EXPECT_NEAR(strip->distance_m, (Eigen::Vector3f(7.0f, 0.01f, 0.0f) - eye).norm(), 1e-3f);
}

TEST(Pick, HiddenClippedAndBackFacingPointsAreNotPicked) {
  const RenderView view = front_view();
  const Eigen::Vector3f right_ray = pixel_ray(view, 440.0, 240.0);
  EXPECT_TRUE(wall()->pick(view.eye, right_ray, {}).has_value());
  EXPECT_FALSE(wall(false, true)->pick(view.eye, right_ray, {}).has_value());
  RenderSettings left_only;
  left_only.culling.clipping.box =
      Eigen::AlignedBox3f(Eigen::Vector3f(9, 0, -1), Eigen::Vector3f(11, 3, 4));
  EXPECT_FALSE(wall()->pick(view.eye, right_ray, left_only).has_value());
  // From behind, the wall faces away.
  const Eigen::Vector3f behind(20.0f, 0.0f, 1.5f);
  EXPECT_FALSE(wall()->pick(behind, Eigen::Vector3f(-1.0f, 0.0f, 0.0f), {}).has_value());
}

}  // namespace
}  // namespace scanbench::render
