// The streaming renderer draws a level-of-detail store: the object tree's
// visibility and colour edits and the scans' corrections applied on the
// device as the CPU's colour pipeline applies them (a hide or a recolour
// uploads no node), and a picture that refines frame by frame within the
// upload limit to the complete one.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "modeling/color_commands.hpp"
#include "modeling/color_pipeline.hpp"
#include "modeling/lod/build_lod.hpp"
#include "modeling/lod/update_lod.hpp"
#include "modeling/room_project.hpp"
#include "modeling/selection_tools.hpp"
#include "modeling/tree_commands.hpp"
#include "render/lod_renderer.hpp"
#include "render/lod_room_store.hpp"
#include "render/object_palette.hpp"
#include "render/pick.hpp"
#include "shared_device.hpp"
#include "support/test_support.hpp"

namespace scanbench::render {
namespace {

// Inside the room (room_project.hpp), looking at the +x wall past the
// committed wall, the floor below.
acquisition::CameraView room_camera() {
  acquisition::CameraView view;
  view.width = 320;
  view.height = 240;
  view.vertical_fov_deg = 60.0;
  view.T_world_camera = acquisition::look_at({-3.0, 0.5, 0.5}, {5.0, -1.5, -0.2});
  return view;
}

RenderSettings every_point() {
  RenderSettings settings;
  settings.culling.level_of_detail = false;
  return settings;
}

// Every 12th pixel of the picture (each way) whose centre the pick finds
// on a point, with what was picked there.
std::vector<std::pair<std::array<int, 2>, LodPick>> picked_pixels(LodRenderer& renderer,
                                                                  const RenderView& view,
                                                                  const RenderSettings& settings) {
  std::vector<std::pair<std::array<int, 2>, LodPick>> out;
  for (int y = 6; y < view.height; y += 12) {
    for (int x = 6; x < view.width; x += 12) {
      const std::optional<LodPick> pick =
          renderer.pick(view.eye, pixel_ray(view, x + 0.5, y + 0.5), settings);
      if (pick) out.push_back({{x, y}, *pick});
    }
  }
  return out;
}

// The room's -x wall grown and committed as object "wall".
modeling::NodeCommandResult commit_wall(store::Project& project, std::int64_t scan) {
  modeling::SelectionTools tools;
  static_cast<void>(tools.select(project, modeling::select_at(scan, -20, 0)));
  return tools.commit(project, {scan, "wall", std::nullopt});
}

std::array<int, 3> pixel(const RenderedImage& image, int x, int y) {
  const std::uint8_t* p = &image.rgba[4 * (static_cast<std::size_t>(y) * image.width + x)];
  return {p[0], p[1], p[2]};
}

// The shaders show each point in the colour the CPU's pipeline gives it
// (modeling/color_pipeline.hpp): the scan's correction, then the owning
// object's edit; hiding an object takes it out of the next frame without
// uploading a node; the palette colours objects as the panorama does. The
// room's surfaces are of one colour each, so a pixel inside one is that
// colour whatever blends there.
TEST(LodRenderer, ShowsThePipelinesColoursHidesAndRecoloursWithoutUploads) {
  test::shared_device();
  const scanbench::test::ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = modeling::store_room(project);
  const modeling::NodeCommandResult wall = commit_wall(project, scan);
  modeling::RecolorSettings recolor;
  recolor.node = wall.node_id;
  recolor.set.hue_deg = 90.0;
  recolor.set.brightness = 10.0;
  recolor.set.saturation = 1.5;
  modeling::recolor_object(project, recolor);
  {
    store::Project::Edit edit = project.begin_command("harmonize", "{}");
    store::ScanColorCorrection gains;
    gains.matrix.diagonal() << 1.1, 1.0, 0.8;
    gains.offset << 0.01, 0.0, 0.02;
    project.put_scan_color_correction(edit, scan, gains);
    edit.commit("{}");
  }
  core::Progress quiet;
  lod::LodBuildSettings build;
  build.threads = 1;
  build.octree.max_leaf_points = 3000;  // a deep tree of a small model
  const std::filesystem::path store = lod::build_lod(project, build, quiet).store;
  ASSERT_EQ(lod::current_lod_store(project), store);

  LodRenderer renderer(store, {});
  renderer.show_project_state(project);
  const RenderView view = make_render_view(room_camera(), renderer.header().origin);
  const LodFrameResult frame = renderer.draw_complete(view, every_point());
  EXPECT_TRUE(frame.complete());
  EXPECT_GT(frame.plan.culled_frustum, 0u);  // the wall behind the camera
  EXPECT_EQ(frame.plan.submitted + frame.plan.culled_frustum, frame.plan.points);
  const RenderedImage shown = renderer.read_image();
  const modeling::ColorPipeline pipeline(project.scan_color_corrections(),
                                         modeling::resolve_color_edits(project.object_nodes()));
  const auto picks = picked_pixels(renderer, view, every_point());
  std::size_t on_wall = 0, agree = 0;
  for (const auto& [at, pick] : picks) {
    on_wall += pick.object == wall.node_id;
    const auto& rgb = pick.point.rgb;
    const std::array<std::uint8_t, 3> expected =
        pipeline.shown(scan, pick.object, {rgb[0], rgb[1], rgb[2]});
    const std::array<int, 3> drawn = pixel(shown, at[0], at[1]);
    bool same = true;
    for (int c = 0; c < 3; ++c) same = same && std::abs(drawn[c] - expected[c]) <= 2;
    agree += same;
  }
  EXPECT_GT(picks.size(), 300u);  // the room fills most of the view
  EXPECT_GT(on_wall, 30u);
  EXPECT_GT(static_cast<double>(agree), 0.97 * static_cast<double>(picks.size()));

  // Hidden: the next frame leaves the wall out, from the nodes on the
  // device (the store is current still: its points did not change).
  modeling::edit_node(project, {wall.node_id, std::nullopt, true, std::nullopt, {}});
  EXPECT_EQ(lod::current_lod_store(project), store);
  renderer.show_project_state(project);
  const LodFrameResult hidden_frame = renderer.draw_complete(view, every_point());
  EXPECT_EQ(hidden_frame.uploaded_nodes, 0u);
  const RenderedImage hidden = renderer.read_image();
  std::size_t gone = 0;
  for (const auto& [at, pick] : picks) {
    if (pick.object == wall.node_id) gone += !hidden.covered(at[0], at[1]);  // nothing behind it
  }
  EXPECT_GT(static_cast<double>(gone), 0.95 * static_cast<double>(on_wall));

  // Colour by object: the palette's colour of each object picked.
  RenderSettings objects = every_point();
  objects.color = ColorMode::kObject;
  renderer.draw_complete(view, objects);
  const RenderedImage by_object = renderer.read_image();
  std::size_t palette = 0, visible = 0;
  for (const auto& [at, pick] : picked_pixels(renderer, view, objects)) {
    const std::array<std::uint8_t, 3> expected =
        object_color(static_cast<std::uint32_t>(pick.object));
    const std::array<int, 3> drawn = pixel(by_object, at[0], at[1]);
    ++visible;
    palette += std::abs(drawn[0] - expected[0]) <= 1 && std::abs(drawn[1] - expected[1]) <= 1 &&
               std::abs(drawn[2] - expected[2]) <= 1;
  }
  EXPECT_GT(static_cast<double>(palette), 0.97 * static_cast<double>(visible));

  // Points that change hands make it out of date, and undoing that does
  // not make it current again (the project changed after it was built).
  modeling::SelectionTools tools;
  static_cast<void>(tools.select(project, modeling::select_at(scan, 0, -45)));
  tools.commit(project, {scan, "floor", std::nullopt});
  EXPECT_FALSE(lod::current_lod_store(project));
  project.undo();
  EXPECT_FALSE(lod::current_lod_store(project));
}

TEST(LodRenderer, RefinesFrameByFrameToTheCompletePicture) {
  test::shared_device();
  const LodRoomStore& room = lod_room_store();
  const std::uint64_t root_bytes = room.hierarchy.nodes[0].points * sizeof(lod::LodPoint);
  LodRendererLimits limits;
  limits.upload_bytes_per_frame = root_bytes;  // a node or so a frame
  LodRenderer streaming(room.store, limits);
  const RenderView view = make_render_view(room_camera(), streaming.header().origin);
  const RenderSettings settings;
  std::uint64_t largest_node = 0;
  for (const lod::LodNodeInfo& node : room.hierarchy.nodes)
    largest_node = std::max<std::uint64_t>(largest_node, node.points * sizeof(lod::LodPoint));
  LodFrameResult frame = streaming.draw(view, settings);
  // The first frame waits for the root alone.
  EXPECT_EQ(frame.plan.draws.size(), 1u);
  EXPECT_EQ(frame.plan.draws.front().node, 0u);
  EXPECT_FALSE(frame.complete());
  std::size_t frames = 1, previous = 0;
  bool grew = true;
  while (!frame.complete() && frames < 2000) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the loader's turn
    frame = streaming.draw(view, settings);
    EXPECT_LE(frame.uploaded_bytes, std::max(root_bytes, largest_node));
    grew = grew && frame.plan.submitted >= previous;
    previous = frame.plan.submitted;
    ++frames;
  }
  ASSERT_TRUE(frame.complete()) << frames << " frames";
  EXPECT_GT(frames, 3u);
  EXPECT_TRUE(grew);
  const RenderedImage refined = streaming.read_image();
  LodRenderer at_once(room.store, {});
  at_once.draw_complete(view, settings);
  EXPECT_EQ(refined.rgba, at_once.read_image().rgba);
  EXPECT_LE(streaming.device_peak_bytes(), at_once.device_peak_bytes());
}

// A still camera refining while nodes are read draws previews within the
// preview budget, then the whole picture once every node is in.
TEST(LodRenderer, RefiningWhileNodesAreReadDrawsPreviewsThenTheWholePicture) {
  test::shared_device();
  const LodRoomStore& room = lod_room_store();
  const std::uint32_t root_points = room.hierarchy.nodes[0].points;
  LodRendererLimits limits;
  limits.upload_bytes_per_frame = root_points * sizeof(lod::LodPoint);  // a node or so a frame
  LodRenderer streaming(room.store, limits);
  const RenderView view = make_render_view(room_camera(), streaming.header().origin);
  RenderSettings settings;
  settings.culling.preview_budget = root_points;
  LodFrameResult frame = streaming.draw(view, settings);
  std::size_t previews = 0, frames = 1;
  while (!frame.complete() && frames < 2000) {
    EXPECT_TRUE(frame.preview);
    EXPECT_LE(frame.plan.submitted, root_points);
    ++previews;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the loader's turn
    frame = streaming.draw(view, settings);
    ++frames;
  }
  ASSERT_TRUE(frame.complete()) << frames << " frames";
  EXPECT_FALSE(frame.preview);
  EXPECT_GT(previews, 0u);
  EXPECT_GT(frame.plan.submitted, std::size_t{root_points});
  LodRenderer at_once(room.store, {});
  at_once.draw_complete(view, settings);
  EXPECT_EQ(streaming.read_image().rgba, at_once.read_image().rgba);
}

// A still picture refines to the finer cells where the whole picture stays
// within its points; else it keeps the coarser ones.
TEST(LodRenderer, AStillPictureRefinesToFinerCellsWithinItsPoints) {
  test::shared_device();
  const LodRoomStore& room = lod_room_store();
  LodRenderer renderer(room.store, {});
  const RenderView view = make_render_view(room_camera(), renderer.header().origin);
  const auto drawn = [&](float fine_lod_pixels, std::size_t fine_points, std::size_t budget) {
    RenderSettings settings;
    settings.culling.lod_pixels = 4.0f;  // coarse enough for the room to have finer cells
    settings.culling.fine_lod_pixels = fine_lod_pixels;
    settings.culling.fine_points = fine_points;
    settings.culling.budget = budget;
    return renderer.draw_complete(view, settings).plan.submitted;
  };
  const std::size_t coarse = drawn(0.0f, 0, 0);
  const std::size_t fine = drawn(1.0f, std::numeric_limits<std::size_t>::max(), 0);
  EXPECT_GT(fine, coarse);
  EXPECT_EQ(drawn(1.0f, fine - 1, 0), coarse);  // the finer picture would hold too many
  EXPECT_EQ(drawn(1.0f, fine, 0), fine);
  // A frame with a budget (a moving one) keeps the coarser cells.
  EXPECT_EQ(drawn(1.0f, fine, fine + coarse), coarse);
}

// A renderer follows an update of its store in place: it uploads only the
// nodes the update rewrote, and draws what a renderer opened on the
// updated store draws, pixel for pixel, the committed object's hide too.
TEST(LodRenderer, FollowsAnUpdateInPlaceKeepingTheNodesItDidNotRewrite) {
  test::shared_device();
  const scanbench::test::ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = modeling::store_room(project);
  core::Progress quiet;
  lod::LodBuildSettings build;
  build.threads = 1;
  build.octree.max_leaf_points = 2000;
  const std::filesystem::path store = lod::build_lod(project, build, quiet).store;
  LodRenderer follower(store, {});
  follower.show_project_state(project);
  const RenderView view = make_render_view(room_camera(), follower.header().origin);
  const LodFrameResult before = follower.draw_complete(view, every_point());
  ASSERT_GT(before.uploaded_nodes, 4u);

  const modeling::NodeCommandResult wall = commit_wall(project, scan);
  std::string why_not;
  const std::optional<lod::LodUpdateResult> updated =
      lod::update_lod(project, build, quiet, why_not);
  ASSERT_TRUE(updated) << why_not;
  ASSERT_FALSE(updated->rewritten.empty());
  ASSERT_LT(updated->rewritten.size(), follower.hierarchy().nodes.size());
  follower.follow_update(updated->rewritten);
  follower.show_project_state(project);
  const LodFrameResult after = follower.draw_complete(view, every_point());
  EXPECT_GT(after.uploaded_nodes, 0u);
  EXPECT_LE(after.uploaded_nodes, updated->rewritten.size());
  LodRenderer fresh(store, {});
  fresh.show_project_state(project);
  fresh.draw_complete(view, every_point());
  EXPECT_EQ(follower.read_image().rgba, fresh.read_image().rgba);
  // The relabelled nodes carry the new object: hiding it hides its points.
  modeling::NodeEdit hide;
  hide.node = wall.node_id;
  hide.hidden = true;
  modeling::edit_node(project, hide);
  follower.show_project_state(project);
  fresh.show_project_state(project);
  const RenderedImage shown = follower.read_image();
  EXPECT_EQ(follower.draw_complete(view, every_point()).uploaded_nodes, 0u);
  fresh.draw_complete(view, every_point());
  EXPECT_EQ(follower.read_image().rgba, fresh.read_image().rgba);
  EXPECT_NE(follower.read_image().rgba, shown.rgba);
}

}  // namespace
}  // namespace scanbench::render
