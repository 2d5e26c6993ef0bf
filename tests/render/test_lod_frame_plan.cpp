// What a frame draws of a level-of-detail store: the room's store walked
// from the root, refined near the eye, thinned far away, within the budget,
// and waiting for the nodes not yet in memory.
#include <gtest/gtest.h>

#include <set>

#include "render/lod_frame_plan.hpp"
#include "render/lod_room_store.hpp"

namespace scanbench::render {
namespace {

const LodHierarchy& room_hierarchy() {
  return lod_room_store().hierarchy;
}

RenderView room_view(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
  acquisition::CameraView camera;
  camera.T_world_camera = acquisition::look_at(position, target);
  return make_render_view(camera, room_hierarchy().header.origin);
}

const auto kAllLoaded = [](std::size_t) { return true; };

TEST(LodFramePlan, NearTheEyeTheTreeIsRefinedToItsLeavesFrontToBack) {
  const LodHierarchy& h = room_hierarchy();
  ASSERT_GT(h.nodes.size(), 20u);
  const LodFramePlan plan =
      plan_lod_frame(h, room_view({0.0, 0.0, 0.0}, {5.0, 0.0, 0.0}), {}, kAllLoaded);
  ASSERT_FALSE(plan.draws.empty());
  EXPECT_TRUE(plan.wanted.empty());
  EXPECT_GT(plan.culled_frustum, 0u);  // the room behind the camera
  EXPECT_LE(plan.submitted, plan.points);
  bool leaf_drawn = false;
  for (std::size_t k = 0; k < plan.draws.size(); ++k) {
    if (k > 0) {
      EXPECT_LE(plan.draws[k - 1].distance_m, plan.draws[k].distance_m);
    }
    leaf_drawn = leaf_drawn || h.nodes[plan.draws[k].node].leaf;
  }
  EXPECT_TRUE(leaf_drawn);
}

TEST(LodFramePlan, FarAwayTheRootsFirstLevelsStandForTheRoom) {
  const LodHierarchy& h = room_hierarchy();
  const LodFramePlan plan =
      plan_lod_frame(h, room_view({-400.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), {}, kAllLoaded);
  ASSERT_EQ(plan.draws.size(), 1u);
  EXPECT_EQ(plan.draws[0].node, 0u);
  EXPECT_LT(plan.submitted, h.nodes[0].points);
  EXPECT_EQ(plan.draws[0].children_drawn, 0u);
  EXPECT_GT(plan.draws[0].cell_m, 0.01f);
}

TEST(LodFramePlan, NodesNotInMemoryAreWantedAndTheirSubtreesWait) {
  const LodHierarchy& h = room_hierarchy();
  const RenderView view = room_view({0.0, 0.0, 0.0}, {5.0, 0.0, 0.0});
  const LodFramePlan root_only = plan_lod_frame(h, view, {}, [](std::size_t k) { return k == 0; });
  ASSERT_EQ(root_only.draws.size(), 1u);
  EXPECT_EQ(root_only.draws[0].count, h.nodes[0].points);  // the root at full detail
  ASSERT_FALSE(root_only.wanted.empty());
  for (const std::size_t k : root_only.wanted) EXPECT_EQ(h.nodes[k].key.depth, 1);
  // Loading what was wanted reaches further down.
  const std::set<std::size_t> loaded(root_only.wanted.begin(), root_only.wanted.end());
  const LodFramePlan next =
      plan_lod_frame(h, view, {}, [&](std::size_t k) { return k == 0 || loaded.count(k) > 0; });
  EXPECT_GT(next.draws.size(), 1u);
  for (const std::size_t k : next.wanted) EXPECT_EQ(h.nodes[k].key.depth, 2);
}

TEST(LodFramePlan, TheBudgetHoldsAndTheClippingCulls) {
  const LodHierarchy& h = room_hierarchy();
  const RenderView view = room_view({0.0, 0.0, 0.0}, {5.0, 0.0, 0.0});
  LodPlanSettings budget;
  budget.budget = 20000;
  const LodFramePlan plan = plan_lod_frame(h, view, budget, kAllLoaded);
  EXPECT_LE(plan.submitted, 20000u);
  EXPECT_GT(plan.stopped_by_budget, 0u);
  LodPlanSettings clipped;
  clipped.clipping.box =
      Eigen::AlignedBox3f(Eigen::Vector3f(100, 100, 100), Eigen::Vector3f(101, 101, 101));
  const LodFramePlan none = plan_lod_frame(h, view, clipped, kAllLoaded);
  EXPECT_TRUE(none.draws.empty());
  EXPECT_EQ(none.culled_clip, h.nodes[0].points_below);
}

}  // namespace
}  // namespace scanbench::render
