// The streaming renderer draws a level-of-detail store as the render model's
// renderer draws the project: the same picture from the stored points, the
// object tree's visibility and colour edits and the scans' corrections
// applied on the device (a hide or a recolour uploads no node), and a
// picture that refines frame by frame within the upload limit to the
// complete one.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "modeling/color_commands.hpp"
#include "modeling/lod/build_lod.hpp"
#include "modeling/room_project.hpp"
#include "modeling/selection_tools.hpp"
#include "modeling/tree_commands.hpp"
#include "render/lod_renderer.hpp"
#include "render/lod_room_store.hpp"
#include "render/render_model.hpp"
#include "render/splat_renderer.hpp"
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

struct Agreement {
  double covered_apart = 0.0;  // share of pixels covered in one picture only
  double psnr_db = 0.0;        // over pixels covered in both
  std::size_t covered = 0;     // in the first
};

Agreement compare(const RenderedImage& a, const RenderedImage& b) {
  std::size_t apart = 0, both = 0, covered = 0;
  double squared = 0.0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      covered += a.covered(x, y);
      if (a.covered(x, y) != b.covered(x, y)) ++apart;
      if (!a.covered(x, y) || !b.covered(x, y)) continue;
      ++both;
      const std::size_t at = 4 * (static_cast<std::size_t>(y) * a.width + x);
      for (int c = 0; c < 3; ++c) {
        const double d = double(a.rgba[at + c]) - double(b.rgba[at + c]);
        squared += d * d;
      }
    }
  }
  const double pixels = static_cast<double>(a.width) * a.height;
  const double mse = both ? squared / (3.0 * static_cast<double>(both)) : 0.0;
  return {static_cast<double>(apart) / pixels,
          mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 99.0, covered};
}

RenderSettings every_point() {
  RenderSettings settings;
  settings.culling.level_of_detail = false;  // the two trees thin differently
  return settings;
}

RenderedImage render_model(const store::Project& project, const RenderSettings& settings) {
  const RenderModel model = build_render_model(project, {});
  SplatRenderer renderer(model);
  renderer.draw(make_render_view(room_camera(), model.origin), settings);
  return renderer.read_image();
}

TEST(LodRenderer, DrawsTheStoreAsTheRenderModelDrawsItsProject) {
  test::shared_device();
  modeling::SelectionTools tools;
  const scanbench::test::ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = modeling::store_room(project);
  static_cast<void>(tools.select(project, modeling::select_at(scan, -20, 0)));
  const modeling::NodeCommandResult wall = tools.commit(project, {scan, "wall", std::nullopt});
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
  const RenderedImage stored = renderer.read_image();
  const Agreement shown = compare(stored, render_model(project, every_point()));
  EXPECT_GT(shown.covered, stored.rgba.size() / 4 / 2);  // the room fills the view
  EXPECT_LT(shown.covered_apart, 0.005);
  EXPECT_GT(shown.psnr_db, 35.0);
  std::printf("shown: %.4f apart, %.1f dB\n", shown.covered_apart, shown.psnr_db);

  // Hidden: the next frame leaves the wall out, from the nodes on the
  // device (the store is as it was; no node is read or uploaded again).
  modeling::edit_node(project, {wall.node_id, std::nullopt, true, std::nullopt, {}});
  EXPECT_EQ(lod::current_lod_store(project), store);  // the tree changed, not its points
  renderer.show_project_state(project);
  const LodFrameResult hidden_frame = renderer.draw_complete(view, every_point());
  EXPECT_EQ(hidden_frame.uploaded_nodes, 0u);
  const RenderedImage hidden = renderer.read_image();
  const Agreement after = compare(hidden, render_model(project, every_point()));
  EXPECT_LT(after.covered, shown.covered - shown.covered / 10);  // the wall is gone
  EXPECT_LT(after.covered_apart, 0.005);
  EXPECT_GT(after.psnr_db, 35.0);
  std::printf("hidden: %.4f apart, %.1f dB\n", after.covered_apart, after.psnr_db);

  // Colour by object: the palette's colours, the wall's now hidden.
  RenderSettings objects = every_point();
  objects.color = ColorMode::kObject;
  renderer.draw_complete(view, objects);
  EXPECT_GT(compare(renderer.read_image(), render_model(project, objects)).psnr_db, 35.0);

  // Points that change hands make it out of date, and undoing that does
  // not make it current again (the project changed after it was built).
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

}  // namespace
}  // namespace scanbench::render
