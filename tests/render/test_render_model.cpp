// The render model read from a project: which points it holds (kept by the
// merge, not deleted; hidden objects marked, not dropped), where they are,
// and how its tiles and nodes let a renderer cull through the tree.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "modeling/geometry_command.hpp"
#include "modeling/import_command.hpp"
#include "modeling/room_project.hpp"
#include "modeling/selection_commands.hpp"
#include "modeling/selection_tools.hpp"
#include "render/render_model.hpp"
#include "support/test_support.hpp"

namespace scanbench::render {
namespace {

// The segmentation's commands build the objects the model draws.
using modeling::delete_node;
using modeling::DeletedPoints;
using modeling::edit_node;
using modeling::group_nodes;
using modeling::NodeCommandResult;
using modeling::select_at;
using modeling::SelectionTools;
using modeling::store_room;

using scanbench::test::ScratchDir;

std::size_t usable_points() {
  const scanbench::test::RoomScan& room = scanbench::test::shared_room();
  std::size_t n = 0;
  for (std::size_t i = 0; i < room.scan.pixel_count(); ++i)
    n += acquisition::in_model(room.scan, room.geometry, i);
  return n;
}

TEST(RenderModel, AnUnsegmentedScanIsTiledWhole) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  RenderModelSettings settings;
  settings.tiles = {4000, 4.0f};
  const RenderModel model = build_render_model(project, settings);
  EXPECT_EQ(model.counts.in_model, usable_points());
  EXPECT_EQ(model.points.size(), usable_points());
  ASSERT_EQ(model.nodes.size(), 1u);  // the unassigned points' root
  EXPECT_EQ(model.roots, std::vector<std::size_t>{0});
  EXPECT_EQ(model.nodes[0].tiles.size(), model.tiles.size());
  EXPECT_GE(model.tiles.size(), 20u);
  std::uint32_t next = 0;
  for (const RenderTile& tile : model.tiles) {
    EXPECT_EQ(tile.first, next);  // tile after tile, nothing between
    next += tile.count;
    EXPECT_LE(tile.count, 4000u);
    EXPECT_LE(tile.box.sizes().maxCoeff(), 4.0f);
    EXPECT_EQ(tile.level_ends.back(), tile.first + tile.count);
    for (std::uint32_t k = tile.first; k < tile.first + tile.count; ++k)
      EXPECT_TRUE(tile.box.contains(model.points.position[k]));
  }
  EXPECT_EQ(next, model.points.size());
  // World positions through the origin: the scanner, rounded to metres.
  const acquisition::Scan stored = project.load_scan(scan);
  EXPECT_EQ(model.origin, stored.T_world_scan.translation().array().round().matrix());
  Eigen::AlignedBox3d world;
  for (const Eigen::Vector3f& p : model.points.position)
    world.extend(model.origin + p.cast<double>());
  Eigen::AlignedBox3d truth = *acquisition::world_bounds(stored);
  EXPECT_TRUE(Eigen::AlignedBox3d(truth.min().array() - 1e-5, truth.max().array() + 1e-5)
                  .contains(world));                       // floats from the origin: 10 µm
  EXPECT_LT((truth.sizes() - world.sizes()).norm(), 0.5);  // mixed pixels dropped, no more
}

TEST(RenderModel, ObjectsAreTiledOnTheirOwnAndCullingFollowsTheTree) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  const NodeCommandResult room = group_nodes(project, {"room", std::nullopt, {}});
  const std::size_t floor_points = tools.select(project, select_at(scan, 0, -45)).selected_pixels;
  const NodeCommandResult floor = tools.commit(project, {scan, "floor", room.node_id});
  const std::size_t wall_points = tools.select(project, select_at(scan, -20, 0)).selected_pixels;
  const NodeCommandResult wall = tools.commit(project, {scan, "wall", room.node_id});
  const std::size_t far_points = tools.select(project, select_at(scan, 90, 0)).selected_pixels;
  const NodeCommandResult far = tools.commit(project, {scan, "far wall", std::nullopt});
  delete_node(project, {far.node_id, DeletedPoints::kDeleted, {}});
  edit_node(project, {room.node_id, std::nullopt, true, std::nullopt, {}});  // hide the room
  RenderModelSettings settings;
  settings.tiles = {8000, 6.0f};
  const RenderModel model = build_render_model(project, settings);
  EXPECT_EQ(model.counts.deleted, far_points);
  EXPECT_EQ(model.counts.hidden, floor_points + wall_points);
  EXPECT_EQ(model.points.size(), usable_points() - far_points);
  ASSERT_EQ(model.nodes.size(), 4u);  // room, floor, wall, unassigned
  EXPECT_EQ(model.roots, (std::vector<std::size_t>{0, 3}));
  EXPECT_EQ(model.nodes[0].children, (std::vector<std::size_t>{1, 2}));
  EXPECT_FALSE(model.nodes[1].shown);  // hidden through its group
  EXPECT_TRUE(model.nodes[3].shown);
  EXPECT_GE(model.nodes[1].tiles.size(), 2u);  // the 10 m floor in 6 m tiles
  std::size_t floor_in_tiles = 0;
  for (const std::size_t t : model.nodes[1].tiles) {
    const RenderTile& tile = model.tiles[t];
    EXPECT_EQ(tile.node, floor.node_id);
    floor_in_tiles += tile.count;
    EXPECT_FALSE(tile.cone.spans_everything());
    EXPECT_GT(tile.cone.axis.z(), 0.99f);  // the floor's normals point up at the scanner
    for (std::uint32_t k = tile.first; k < tile.first + tile.count; ++k)
      EXPECT_EQ(model.points.node[k], static_cast<std::uint32_t>(floor.node_id));
    EXPECT_TRUE(model.nodes[0].box.contains(tile.box));  // the group's box holds it
  }
  EXPECT_EQ(floor_in_tiles, floor_points);
  EXPECT_TRUE(model.nodes[0].box.contains(model.nodes[2].box));
  EXPECT_EQ(model.tiles[model.nodes[2].tiles.front()].node, wall.node_id);
}

TEST(RenderModel, OnlyWhatTheMergeKeptUnlessAskedForAll) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  std::vector<std::uint8_t> keep(scanbench::test::shared_room().scan.pixel_count());
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = i % 3 != 0;
  store::Project::Edit edit = project.begin_command("merge", "{}");
  project.put_layer(
      edit, scan,
      store::encode_layer<std::uint8_t>(store::layer::kKeep, store::ElementType::kU8, keep));
  edit.commit("{}");
  const RenderModel merged = build_render_model(project, {});
  EXPECT_GT(merged.counts.merged_away, usable_points() / 4);
  EXPECT_EQ(merged.points.size(), usable_points() - merged.counts.merged_away);
  RenderModelSettings all;
  all.merged_only = false;
  EXPECT_EQ(build_render_model(project, all).points.size(), usable_points());
}

// An unstructured cloud's footprint is its point spacing on the surface:
// its splats are round, with no beam to stretch them.
TEST(RenderModel, AnUnstructuredCloudIsDrawnWithRoundSplatsOfItsSpacing) {
  const ScratchDir dir;
  core::Progress quiet;
  const std::vector<std::filesystem::path> files = {
      scanbench::test::fixture("good/e57/unstructured_sphere.e57")};
  modeling::import_scan_files(dir / "p.sbproj", files, {}, quiet);
  store::Project project = store::Project::open(dir / "p.sbproj");
  modeling::geometry_project(project, {}, quiet);
  const RenderModel model = build_render_model(project, {});
  ASSERT_EQ(model.points.size(), 4000u);
  // 4 000 points on a sphere of radius 1 m: about 5.6 cm apart.
  for (std::size_t k = 0; k < model.points.size(); ++k) {
    EXPECT_EQ(model.points.radii_m[k].x(), model.points.radii_m[k].y());
    EXPECT_GT(model.points.radii_m[k].x(), 0.02f);
    EXPECT_LT(model.points.radii_m[k].x(), 0.08f);
    EXPECT_EQ(model.points.major_axis[k], Eigen::Vector3f::Zero());
  }
}

TEST(RenderModel, AScanWithoutGeometryIsRefusedByName) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  scanbench::test::insert_committed(project, scanbench::test::shared_room().scan);
  try {
    build_render_model(project, {});
    ADD_FAILURE() << "built without geometry";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("scan 1"));
    EXPECT_THAT(error.what(), ::testing::HasSubstr("scanbench geometry"));
  }
}

}  // namespace
}  // namespace scanbench::render
