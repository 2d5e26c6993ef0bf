// The segmentation's commands on a project: regions grown into a selection,
// committed as objects, the tree edited, and every change undone and redone
// exactly, across processes, for a long random session too.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>

#include "core/errors.hpp"
#include "modeling/carried_objects.hpp"
#include "modeling/node_tree.hpp"
#include "modeling/scan_cache.hpp"
#include "modeling/selection_commands.hpp"
#include "modeling/selection_tools.hpp"
#include "modeling/store/typed_layers.hpp"
#include "project_test_support.hpp"
#include "room_project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;
using ::testing::HasSubstr;

std::size_t count_owned(const store::Project& project, std::int64_t scan, std::uint32_t owner) {
  const auto membership =
      project.load_layer<std::uint32_t>(scan, store::layer::kMembership, store::ElementType::kU32);
  if (!membership) return owner == 0 ? test::shared_room().scan.pixel_count() : 0;
  return static_cast<std::size_t>(std::count(membership->begin(), membership->end(), owner));
}

// Everything a segmentation session changes: the tree and each scan's
// selection and membership, bit for bit.
std::string state_of(const store::Project& project) {
  std::ostringstream out;
  out.precision(17);  // every bit of a coordinate
  for (const store::ObjectNode& n : project.object_nodes()) {
    out << n.id << '|' << n.name << '|' << static_cast<int>(n.kind) << '|' << n.parent.value_or(-1)
        << '|' << n.hidden << '|' << n.points << '|' << n.mean_footprint_m.value_or(-1.0);
    if (n.bbox_world)
      out << '|' << n.bbox_world->min().transpose() << n.bbox_world->max().transpose();
    out << '\n';
  }
  for (const store::StoredScanSummary& s : project.scans()) {
    for (const char* name : {store::layer::kSelection, store::layer::kMembership}) {
      out << s.id << name;
      if (const auto u8 = project.load_layer<std::uint8_t>(
              s.id, name,
              name == std::string(store::layer::kSelection) ? store::ElementType::kU8
                                                            : store::ElementType::kU32)) {
        out << std::string(u8->begin(), u8->end());
      }
    }
  }
  return out.str();
}

// A commit carries the object into the other scans with the settings its
// selection was grown with in this session: the last grow that replaced or
// added to it (a subtraction's do not count, nor a grow whose seed was
// refused), and none before any. The journal keeps them with the commit.
TEST(SegmentCommands, ACommitGrowsOnWithTheSettingsItsSelectionWasGrownWith) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  SelectionTools tools;
  EXPECT_FALSE(tools.commit_of(scan, "wall", std::nullopt).grow.has_value());
  SelectSettings range =
      select_at(scan, 20, 0, SelectMode::kReplace, segmentation::Channel::kRange);
  range.grow.tolerance = 9.0;
  ASSERT_TRUE(tools.select(project, range).seed_open);
  ASSERT_TRUE(tools.select(project, select_at(scan, 0, -45, SelectMode::kSubtract)).seed_open);
  SelectSettings outside_lasso =
      select_at(scan, -20, 0, SelectMode::kAdd, segmentation::Channel::kIntensity);
  outside_lasso.constraints.lasso = {{0.0, 0.0}, {5.0, 0.0}, {0.0, 5.0}};
  ASSERT_FALSE(tools.select(project, outside_lasso).seed_open);
  const CommitSettings commit = tools.commit_of(scan, "wall", 7);
  EXPECT_EQ(commit.scan_id, scan);
  EXPECT_EQ(commit.name, "wall");
  EXPECT_EQ(commit.parent, std::optional<std::int64_t>(7));
  ASSERT_TRUE(commit.grow.has_value());
  EXPECT_EQ(commit.grow->channel, segmentation::Channel::kRange);
  EXPECT_EQ(commit.grow->tolerance, 9.0);
  EXPECT_FALSE(tools.commit_of(scan + 1, "wall", std::nullopt).grow.has_value());
  tools.commit(project, tools.commit_of(scan, "wall", std::nullopt));
  EXPECT_THAT(project.history().back().settings, HasSubstr("\"grow\":{\"channel\":\"range\""));
}

TEST(SegmentCommands, AGrownWallBecomesAnObjectOfTheTree) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  SelectionTools tools;
  const NodeCommandResult room = group_nodes(project, {"room", std::nullopt, {}});
  const std::size_t journal = project.history().size();
  const SelectResult selected = tools.select(project, select_at(scan, -20, 0));
  ASSERT_TRUE(selected.seed_open);
  EXPECT_GT(selected.selected_pixels, 10000u);
  EXPECT_EQ(project.history().size(), journal);  // a grow is session state
  const NodeCommandResult wall = tools.commit(project, {scan, "wall +x", room.node_id});
  EXPECT_TRUE(tools.selection(scan).empty());
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[1].id, wall.node_id);
  EXPECT_EQ(nodes[1].parent, room.node_id);
  EXPECT_EQ(nodes[1].points, static_cast<std::int64_t>(selected.selected_pixels));
  EXPECT_EQ(nodes[0].points, nodes[1].points);  // the group sums its objects
  ASSERT_TRUE(nodes[1].bbox_world.has_value());
  // The wall's plane, its reveals 0.3 m deep, and the pixels on its creases.
  EXPECT_GT(nodes[1].bbox_world->min().x(), 4.9);
  EXPECT_LT(nodes[1].bbox_world->max().x(), 5.31);
  EXPECT_GT(*nodes[1].mean_footprint_m, 0.0);
  EXPECT_EQ(count_owned(project, scan, static_cast<std::uint32_t>(wall.node_id)),
            selected.selected_pixels);
  // The wall's pixels are no longer in the pool: a click on them grows
  // nothing and says why. No click writes, so an undone command stays redoable.
  group_nodes(project, {"later", std::nullopt, {}});
  ASSERT_TRUE(project.undo().has_value());
  const std::size_t after_undo = project.history().size();
  ASSERT_TRUE(tools.select(project, select_at(scan, 0, -45)).seed_open);  // the floor
  const SelectResult refused = tools.select(project, select_at(scan, -20, 0));
  EXPECT_FALSE(refused.seed_open);
  EXPECT_THAT(refused.refused, HasSubstr("owns it"));
  EXPECT_EQ(project.history().size(), after_undo);
  EXPECT_TRUE(project.redo().has_value());  // the redo chain is whole
}

// Selections are session state: undo takes the grows back one by one, and
// undoing a commit brings its selection back; keep() stores them in the
// project for the next session, as one command, only when they changed.
TEST(SegmentCommands, SelectionsAreSessionStateKeptOnRequest) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  SelectionTools tools;
  const std::size_t wall = tools.select(project, select_at(scan, -20, 0)).selected_pixels;
  const std::size_t both =
      tools.select(project, select_at(scan, 0, -45, SelectMode::kAdd)).selected_pixels;
  ASSERT_GT(both, wall);
  ASSERT_TRUE(tools.undo_selection());
  EXPECT_EQ(tools.selection(scan).size(), wall);
  ASSERT_TRUE(tools.redo_selection());
  EXPECT_EQ(tools.selection(scan).size(), both);
  const NodeCommandResult committed = tools.commit(project, tools.commit_of(scan, "both", {}));
  EXPECT_FALSE(tools.undo_selection());  // the grows before a command go with it
  ASSERT_TRUE(project.undo().has_value());
  tools.command_undone(project, committed.command_id);
  EXPECT_EQ(tools.selection(scan).size(), both);
  ASSERT_TRUE(project.redo().has_value());
  tools.command_redone(project, committed.command_id);
  EXPECT_TRUE(tools.selection(scan).empty());
  ASSERT_TRUE(project.undo().has_value());
  tools.command_undone(project, committed.command_id);
  // A grow after the undo, taken back and made again: redoing the commit
  // would pass over it.
  EXPECT_FALSE(tools.grown_since_command());
  ASSERT_TRUE(tools.select(project, select_at(scan, 0, -45, SelectMode::kSubtract)).seed_open);
  ASSERT_TRUE(tools.undo_selection());
  EXPECT_FALSE(tools.grown_since_command());
  ASSERT_TRUE(tools.redo_selection());
  EXPECT_TRUE(tools.grown_since_command());
  ASSERT_TRUE(tools.undo_selection());

  EXPECT_TRUE(kept_selection(project, scan).empty());
  const std::size_t journal = project.history().size();
  // Kept when a session ends, it would end the redo chain: it is held back.
  const SelectionTools::Kept spared = tools.keep(project, true);
  EXPECT_TRUE(spared.held_back);
  EXPECT_EQ(spared.command_id, 0);
  EXPECT_EQ(project.history().size(), journal);
  // Asked for, it is kept, and ends it: the undone commit gives its place.
  const SelectionTools::Kept kept = tools.keep(project, false);
  EXPECT_GT(kept.command_id, 0);
  EXPECT_EQ(project.history().size(), journal);
  EXPECT_EQ(kept_selection(project, scan), tools.selection(scan));
  EXPECT_EQ(tools.keep(project, false).command_id, 0);  // nothing changed since
  // Another session starts from the kept selection, and a commit removes it.
  SelectionTools next;
  next.open_scan(project, scan);
  EXPECT_EQ(next.selection(scan).size(), both);
  next.commit(project, next.commit_of(scan, "both", {}));
  EXPECT_TRUE(kept_selection(project, scan).empty());
}

// Three setups of the room: two at the same spot, and a third 100 m
// away (registered there); their scan ids.
std::array<std::int64_t, 3> two_rooms_and_a_far_one(store::Project& project) {
  const std::int64_t first = store_room(project);
  const std::int64_t second = store_room(project);
  const std::int64_t far = store_room(project);
  acquisition::Scan moved = test::shared_room().scan;
  moved.T_world_scan.translation() = Eigen::Vector3d(100.0, 0.0, 0.0);
  store::Project::Edit edit = project.begin_command("register", "{}");
  project.set_pose(edit, far, moved);
  edit.commit("{}");
  return {first, second, far};
}

// An object drawn in one scan covers the surface in every scan that saw it:
// a second setup at the same spot gives the wall its points, in the same
// command; a setup 100 m away sees other surfaces and gives none; points an
// object of the other scan owns stay its own.
TEST(SegmentCommands, ACommittedObjectTakesTheOtherScansPointsOnItsSurface) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const auto [first, second, far] = two_rooms_and_a_far_one(project);
  // The poster, flush with the wall, is already an object of the second scan.
  ASSERT_TRUE(tools
                  .select(project, select_at(second, 31, 0, SelectMode::kReplace,
                                             segmentation::Channel::kColor))
                  .seed_open);
  CommitSettings poster{second, "poster", std::nullopt};
  poster.other_scans = false;
  const NodeCommandResult poster_node = tools.commit(project, poster);
  const std::size_t poster_pixels =
      count_owned(project, second, static_cast<std::uint32_t>(poster_node.node_id));
  ASSERT_GT(poster_pixels, 100u);

  const SelectResult selected = tools.select(project, select_at(first, 20, 0));
  const NodeCommandResult wall = tools.commit(project, {first, "wall +x", std::nullopt});
  const auto id = static_cast<std::uint32_t>(wall.node_id);
  const std::size_t in_first = count_owned(project, first, id);
  EXPECT_EQ(in_first, selected.selected_pixels);
  // The same pixels of the second scan join, but those the poster owns.
  const auto layer = [&](std::int64_t scan) {
    return *project.load_layer<std::uint32_t>(scan, store::layer::kMembership,
                                              store::ElementType::kU32);
  };
  const std::vector<std::uint32_t> drawn = layer(first), other = layer(second);
  std::size_t expected = 0, poster_kept = 0;
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    if (drawn[i] != id) continue;
    expected += other[i] == id;
    poster_kept += other[i] == static_cast<std::uint32_t>(poster_node.node_id);
  }
  EXPECT_EQ(expected + poster_kept, in_first);
  EXPECT_GT(poster_kept, 0u);  // the wall's region holds the poster, flush with it
  EXPECT_EQ(count_owned(project, second, id), expected);
  EXPECT_EQ(count_owned(project, far, id), 0u);
  // The user sees which scans it covers.
  const ScanCoverage coverage = scan_coverage(project);
  const std::map<std::int64_t, std::int64_t> wall_scans = {
      {first, static_cast<std::int64_t>(in_first)}, {second, static_cast<std::int64_t>(expected)}};
  EXPECT_EQ(coverage.at(wall.node_id), wall_scans);
  for (const store::ObjectNode& node : project.object_nodes()) {
    if (node.id != wall.node_id) continue;
    EXPECT_EQ(node.points, static_cast<std::int64_t>(in_first + expected));
  }
  const std::vector<store::CommandRecord> history = project.history();
  EXPECT_THAT(history.back().result,
              HasSubstr("\"other_scans_points\":" + std::to_string(expected)));
  // One command: undo takes the wall out of both scans.
  project.undo();
  EXPECT_EQ(count_owned(project, first, id), 0u);
  EXPECT_EQ(count_owned(project, second, id), 0u);
  EXPECT_EQ(count_owned(project, second, static_cast<std::uint32_t>(poster_node.node_id)),
            poster_pixels);
  // Asked to stay in its scan, it does.
  project.redo();
  project.undo();
  ASSERT_TRUE(tools.select(project, select_at(first, 20, 0)).seed_open);
  CommitSettings alone{first, "wall +x", std::nullopt};
  alone.other_scans = false;
  const auto only = static_cast<std::uint32_t>(tools.commit(project, alone).node_id);
  EXPECT_EQ(count_owned(project, first, only), in_first);
  EXPECT_EQ(count_owned(project, second, only), 0u);
}

// A selection drawn in the 3D view spans scans: it is one step of the
// selection's undo, and its commit makes one object that each scan
// completes from the others' parts (the points the merge left out).
TEST(SegmentCommands, ASelectionSpanningScansIsOneStepAndOneObject) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const auto [first, second, far] = two_rooms_and_a_far_one(project);
  // A wall grown in the first scan, then the same wall drawn in 3D: its
  // pixels split between the two scans as the merge would keep them.
  ASSERT_TRUE(tools.select(project, select_at(first, 20, 0)).seed_open);
  const segmentation::PixelSet wall = tools.selection(first);
  ASSERT_GT(wall.size(), 200u);
  const std::size_t half = wall.size() / 2;
  const segmentation::PixelSet a(wall.begin(), wall.begin() + static_cast<std::ptrdiff_t>(half));
  const segmentation::PixelSet b(wall.begin() + static_cast<std::ptrdiff_t>(half), wall.end());
  EXPECT_EQ(tools.select_pixels(project, {{first, a}, {second, b}}, SelectMode::kReplace),
            wall.size());
  EXPECT_EQ(tools.selected_scans(), 2u);
  EXPECT_EQ(tools.selection(first), a);
  EXPECT_EQ(tools.selection(second), b);
  // Adding and subtracting change only the scans named.
  EXPECT_EQ(tools.select_pixels(project, {{second, a}}, SelectMode::kAdd), wall.size() + half);
  EXPECT_EQ(tools.select_pixels(project, {{second, a}}, SelectMode::kSubtract), wall.size());
  // One step each: the replace undone gives the grown selection back.
  ASSERT_TRUE(tools.undo_selection());
  ASSERT_TRUE(tools.undo_selection());
  ASSERT_TRUE(tools.undo_selection());
  EXPECT_EQ(tools.selection(first), wall);
  EXPECT_TRUE(tools.selection(second).empty());
  ASSERT_TRUE(tools.redo_selection());
  EXPECT_EQ(tools.selection(second), b);
  // A pixel outside a grid is refused, and nothing changes.
  EXPECT_THROW(tools.select_pixels(project, {{second, {0, 1u << 30}}}, SelectMode::kAdd),
               core::InputError);
  EXPECT_THROW(tools.select_pixels(project, {{9999, {0}}}, SelectMode::kAdd), core::InputError);
  EXPECT_EQ(tools.selection(second), b);

  // One object: each scan takes its part, and the other's from the other.
  const std::string before = state_of(project);
  const NodeCommandResult made = tools.commit_all(project, first, "wall +x", std::nullopt);
  const auto id = static_cast<std::uint32_t>(made.node_id);
  EXPECT_EQ(count_owned(project, first, id), wall.size());
  EXPECT_EQ(count_owned(project, second, id), wall.size());
  EXPECT_EQ(count_owned(project, far, id), 0u);
  EXPECT_EQ(tools.selected_pixels(), 0u);
  EXPECT_THAT(project.history().back().result,
              HasSubstr("\"points\":" + std::to_string(wall.size())));
  // Undone, the project is as before and both scans' selections are back.
  project.undo();
  tools.command_undone(project, made.command_id);
  EXPECT_EQ(state_of(project), before);
  EXPECT_EQ(tools.selection(first), a);
  EXPECT_EQ(tools.selection(second), b);
  project.redo();
  tools.command_redone(project, made.command_id);
  EXPECT_EQ(tools.selected_pixels(), 0u);
  EXPECT_EQ(count_owned(project, second, id), wall.size());
}

// When the scans move (a re-registration), the points an object took from
// other scans follow: those no longer on its surface go back to the pool,
// and a scan now over it (moved there, or imported later and registered)
// gets its points, grown with the settings of the commit.
TEST(SegmentCommands, CarriedPointsFollowTheScansNewPoses) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t first = store_room(project);
  const std::int64_t second = store_room(project);
  const std::int64_t later = store_room(project);
  const Eigen::Isometry3d here = test::shared_room().scan.T_world_scan;
  Eigen::Isometry3d away = here;
  away.translation() += Eigen::Vector3d(100.0, 0.0, 0.0);
  {
    store::Project::Edit edit = project.begin_command("register", "{}");
    acquisition::Scan moved = test::shared_room().scan;
    moved.T_world_scan = away;
    project.set_pose(edit, later, moved);
    edit.commit("{}");
  }
  SelectionTools tools;
  ASSERT_TRUE(tools.select(project, select_at(first, 20, 0)).seed_open);
  const auto wall = static_cast<std::uint32_t>(
      tools.commit(project, tools.commit_of(first, "wall +x", std::nullopt)).node_id);
  const std::size_t in_second = count_owned(project, second, wall);
  ASSERT_GT(in_second, 1000u);
  ASSERT_EQ(count_owned(project, later, wall), 0u);

  // A registration swaps them: the second scan moves away, the later one comes.
  core::Progress quiet;
  const std::vector<store::StoredScanSummary> scans = project.scans();
  std::vector<std::int64_t> ids;
  for (const store::StoredScanSummary& scan : scans) ids.push_back(scan.id);
  ASSERT_EQ(ids, (std::vector<std::int64_t>{first, second, later}));
  CachedScans stream(project, ids, std::uint64_t{1} << 40, 1, "register", quiet);
  const CarriedAgain again = carry_objects_again(project, scans, stream, {here, away, here}, quiet);
  EXPECT_EQ(again.released, in_second);
  EXPECT_EQ(again.carried_points, in_second);
  EXPECT_EQ(again.memberships.count(first), 0u);  // drawn there: unchanged
  const auto owned = [&](std::int64_t scan) {
    const std::vector<std::uint32_t>& m = again.memberships.at(scan);
    return static_cast<std::size_t>(std::count(m.begin(), m.end(), wall));
  };
  EXPECT_EQ(owned(second), 0u);
  EXPECT_EQ(owned(later), in_second);
  const std::vector<std::uint8_t>& carried = again.carried.at(later);
  EXPECT_EQ(static_cast<std::size_t>(std::count(carried.begin(), carried.end(), 1)), in_second);
  // Nothing moved: nothing changes.
  std::vector<Eigen::Isometry3d> where_they_are;
  for (const store::StoredScanSummary& scan : scans)
    where_they_are.push_back(scan.summary.T_world_scan);
  EXPECT_TRUE(
      carry_objects_again(project, scans, stream, where_they_are, quiet).memberships.empty());
}

// A review's rejected proposals go in one command, its accepted ones move
// in one: one undo each.
TEST(SegmentCommands, SeveralNodesAreDeletedOrMovedInOneCommand) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  const NodeCommandResult site = group_nodes(project, {"site", std::nullopt, {}});
  ProposeSettings settings;
  settings.scan_id = scan;
  settings.parent = site.node_id;
  const SeparateResult proposed = propose_objects(project, settings);
  ASSERT_GE(proposed.nodes.size(), 4u);
  const std::string before = state_of(project);
  const std::size_t journal = project.history().size();
  delete_node(project, {proposed.nodes[0], DeletedPoints::kToPool, {proposed.nodes[1]}});
  EXPECT_EQ(project.history().size(), journal + 1);
  EXPECT_EQ(project.object_nodes().size(), 2 + proposed.nodes.size() - 2);
  EXPECT_EQ(count_owned(project, scan, static_cast<std::uint32_t>(proposed.nodes[1])), 0u);
  NodeEdit accept;
  accept.node = proposed.nodes[2];
  accept.parent = site.node_id;
  accept.others = {proposed.nodes[3]};
  edit_node(project, accept);
  EXPECT_EQ(project.history().size(), journal + 2);
  for (const store::ObjectNode& n : project.object_nodes()) {
    if (n.id == proposed.nodes[2] || n.id == proposed.nodes[3]) {
      EXPECT_EQ(n.parent, site.node_id);
    }
  }
  ASSERT_TRUE(project.undo().has_value());
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(state_of(project), before);
}

TEST(SegmentCommands, AddSubtractAndUndoRedoAcrossProcesses) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  std::int64_t scan = 0;
  std::size_t wall_only = 0;
  std::size_t committed = 0;
  std::string before_commit;
  {
    store::Project project = store::Project::create(dir / "p.sbproj");
    scan = store_room(project);
    wall_only = tools.select(project, select_at(scan, -20, 0)).selected_pixels;
    const SelectResult both = tools.select(project, select_at(scan, 0, -45, SelectMode::kAdd));
    EXPECT_GT(both.selected_pixels, wall_only);  // the floor joined
    // The floor's region also holds the pixels on its crease with the wall.
    const SelectResult back = tools.select(project, select_at(scan, 0, -45, SelectMode::kSubtract));
    EXPECT_LE(back.selected_pixels, wall_only);
    EXPECT_GT(back.selected_pixels, wall_only * 98 / 100);
    committed = back.selected_pixels;
    before_commit = state_of(project);
    tools.commit(project, {scan, "wall", std::nullopt});
  }
  {
    store::Project project = store::Project::open(dir / "p.sbproj");
    ASSERT_TRUE(project.undo().has_value());
    EXPECT_EQ(state_of(project), before_commit);
  }
  store::Project project = store::Project::open(dir / "p.sbproj");
  ASSERT_TRUE(project.redo().has_value());
  EXPECT_EQ(project.object_nodes().size(), 1u);
  EXPECT_EQ(project.object_nodes()[0].points, static_cast<std::int64_t>(committed));
}

TEST(SegmentCommands, DeletedObjectsGiveTheirPointsBackOrMarkThemDeleted) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  const NodeCommandResult room = group_nodes(project, {"room", std::nullopt, {}});
  const std::size_t floor = tools.select(project, select_at(scan, 0, -45)).selected_pixels;
  const NodeCommandResult object = tools.commit(project, {scan, "floor", room.node_id});
  delete_node(project, {room.node_id, DeletedPoints::kDeleted, {}});
  EXPECT_TRUE(project.object_nodes().empty());  // the group and the floor in it
  EXPECT_EQ(count_owned(project, scan, store::kDeletedPoints), floor);
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(count_owned(project, scan, static_cast<std::uint32_t>(object.node_id)), floor);
  delete_node(project, {object.node_id, DeletedPoints::kToPool, {}});
  EXPECT_EQ(project.object_nodes().size(), 1u);
  EXPECT_EQ(project.object_nodes()[0].points, 0);
  EXPECT_TRUE(tools.select(project, select_at(scan, 0, -45)).seed_open);
}

TEST(SegmentCommands, UngroupMovesTheChildrenUpAndKeepsTheirPoints) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  const NodeCommandResult site = group_nodes(project, {"site", std::nullopt, {}});
  const NodeCommandResult room = group_nodes(project, {"room", site.node_id, {}});
  tools.select(project, select_at(scan, 0, -45));
  const NodeCommandResult floor = tools.commit(project, {scan, "floor", room.node_id});
  const ScanCoverage coverage = scan_coverage(project);
  EXPECT_EQ(coverage.at(site.node_id), coverage.at(floor.node_id));  // a group sums its objects
  const std::string before = state_of(project);
  const UngroupResult ungrouped = ungroup_node(project, room.node_id);
  EXPECT_EQ(ungrouped.children, std::vector<std::int64_t>{floor.node_id});
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  ASSERT_EQ(nodes.size(), 2u);  // the site and the floor
  EXPECT_EQ(nodes[1].id, floor.node_id);
  EXPECT_EQ(nodes[1].parent, site.node_id);
  EXPECT_EQ(nodes[0].points, nodes[1].points);  // the site still sums the floor
  try {
    ungroup_node(project, floor.node_id);
    ADD_FAILURE() << "an object was ungrouped";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("not a group"));
  }
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(state_of(project), before);
}

TEST(SegmentCommands, MovingAScanMovesItsObjectsBoxes) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  const NodeCommandResult room = group_nodes(project, {"room", std::nullopt, {}});
  tools.select(project, select_at(scan, -20, 0));
  tools.commit(project, {scan, "wall +x", room.node_id});
  const std::vector<store::ObjectNode> before = project.object_nodes();
  const Eigen::Vector3d shift(10.0, -2.0, 0.5);
  const Eigen::Isometry3d moved =
      Eigen::Translation3d(shift) * project.load_scan(scan).T_world_scan;
  const std::vector<store::ObjectNode> after = node_figures_after_moving(project, {{scan, moved}});
  ASSERT_EQ(after.size(), 2u);  // the wall and its group
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(after[k].id, before[k].id);
    EXPECT_EQ(after[k].points, before[k].points);
    EXPECT_TRUE(after[k].bbox_world->min().isApprox(before[k].bbox_world->min() + shift, 1e-12));
    EXPECT_TRUE(after[k].bbox_world->max().isApprox(before[k].bbox_world->max() + shift, 1e-12));
  }
  EXPECT_TRUE(node_figures_after_moving(project, {}).empty());  // nothing moved, nothing stale
}

TEST(SegmentCommands, SeparateSplitsAnObjectIntoItsParts) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  const std::size_t pane = tools.select(project, select_at(scan, 0, 8)).selected_pixels;
  const std::size_t both =
      tools.select(project, select_at(scan, 36, 0, SelectMode::kAdd, segmentation::Channel::kColor))
          .selected_pixels;
  const NodeCommandResult object = tools.commit(project, {scan, "pane and poster", std::nullopt});
  const SeparateResult parts = separate_object(project, {object.node_id, scan});
  ASSERT_EQ(parts.nodes.size(), 2u);
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[1].name, "pane and poster 2");
  EXPECT_EQ(nodes[0].points + nodes[1].points, static_cast<std::int64_t>(both));
  EXPECT_TRUE(nodes[0].points == static_cast<std::int64_t>(pane) ||
              nodes[1].points == static_cast<std::int64_t>(pane));
  // Merged back: one object with both parts, its figures whole again.
  const NodeCommandResult merged = merge_objects(project, {{parts.nodes[1], parts.nodes[0]}});
  EXPECT_EQ(merged.node_id, parts.nodes[1]);
  ASSERT_EQ(project.object_nodes().size(), 1u);
  EXPECT_EQ(project.object_nodes()[0].points, static_cast<std::int64_t>(both));
  EXPECT_EQ(count_owned(project, scan, static_cast<std::uint32_t>(parts.nodes[1])), both);
  ASSERT_TRUE(project.undo().has_value());
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(project.object_nodes().size(), 1u);
}

TEST(SegmentCommands, ProposalsCoverThePoolInOneUndoableCommand) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  tools.select(project, select_at(scan, 0, -45));
  const NodeCommandResult floor = tools.commit(project, {scan, "floor", std::nullopt});
  const std::string before = state_of(project);
  ProposeSettings settings;
  settings.scan_id = scan;
  const SeparateResult proposed = propose_objects(project, settings);
  ASSERT_GE(proposed.nodes.size(), 5u);  // four walls and the pane at least
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  EXPECT_EQ(nodes[1].name, "proposals");
  EXPECT_EQ(nodes[1].kind, store::NodeKind::kGroup);
  EXPECT_EQ(nodes[0].id, floor.node_id);
  EXPECT_EQ(nodes[0].points, static_cast<std::int64_t>(count_owned(
                                 project, scan, static_cast<std::uint32_t>(floor.node_id))));
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(state_of(project), before);
}

TEST(SegmentCommands, RefusedCommandsNameTheProblemAndWriteNothing) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t scan = store_room(project);
  const NodeCommandResult site = group_nodes(project, {"site", std::nullopt, {}});
  const NodeCommandResult hall = group_nodes(project, {"hall", site.node_id, {}});
  const std::int64_t revision = project.revision();
  const auto refused = [&](auto&& command, const char* expected) {
    try {
      command();
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const core::InputError& error) {
      EXPECT_THAT(error.what(), HasSubstr(expected));
    }
    EXPECT_EQ(project.revision(), revision) << expected;
  };
  SelectSettings outside = select_at(scan, 0, 0);
  outside.seed_row = 180;
  refused([&] { tools.select(project, outside); }, "outside the 180 × 720 grid");
  refused([&] { tools.commit(project, {scan, "wall", std::nullopt}); }, "selection is empty");
  refused([&] { tools.commit(project, {scan, "", std::nullopt}); }, "needs a name");
  refused([&] { group_nodes(project, {"x", 99, {}}); }, "node 99");
  refused(
      [&] {
        edit_node(project, {site.node_id, std::nullopt, std::nullopt, hall.node_id, {}});
      },
      "below itself");
  refused([&] { delete_node(project, {42, DeletedPoints::kToPool, {}}); }, "node 42");
  refused([&] { merge_objects(project, {{site.node_id, hall.node_id}}); }, "is a group");
  refused([&] { merge_objects(project, {{site.node_id}}); }, "two objects or more");
}

// What must hold after every command: each parent is a live group, and each
// object's point count is what the membership layer gives it (a group's, the
// sum below it).
void expect_consistent_tree(const store::Project& project, std::int64_t scan, int step) {
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  std::map<std::int64_t, const store::ObjectNode*> by_id;
  for (const store::ObjectNode& n : nodes) by_id[n.id] = &n;
  std::map<std::int64_t, std::int64_t> owned;  // points below each node
  const auto membership =
      project.load_layer<std::uint32_t>(scan, store::layer::kMembership, store::ElementType::kU32);
  if (membership) {
    for (const std::uint32_t owner : *membership) {
      if (owner == 0 || owner == store::kDeletedPoints) continue;
      ASSERT_TRUE(by_id.count(owner)) << "step " << step << ": pixels of a removed node " << owner;
      for (std::optional<std::int64_t> at = owner; at; at = by_id.at(*at)->parent) ++owned[*at];
    }
  }
  for (const store::ObjectNode& n : nodes) {
    if (n.parent) {
      ASSERT_TRUE(by_id.count(*n.parent)) << "step " << step << ": node " << n.id;
      EXPECT_EQ(by_id.at(*n.parent)->kind, store::NodeKind::kGroup) << "step " << step;
    }
    EXPECT_EQ(n.points, owned[n.id]) << "step " << step << ": node " << n.id;
  }
}

std::int64_t newest_done(const store::Project& project) {
  std::int64_t newest = 0;
  for (const store::CommandRecord& c : project.history()) {
    if (c.state == store::CommandState::kDone) newest = c.id;
  }
  return newest;
}

// The property: a long random session of every operation, then undo until
// the session's first command is gone, leaves the state it began with.
// A thousand random operations in the Release build; under the sanitizers,
// where each costs about eight times as much, 250.
TEST(SegmentCommands, RandomOperationsUndoneRestoreTheStateExactly) {
  constexpr int kOperations = SCANBENCH_SANITIZED ? 250 : 1000;
  SelectionTools tools;  // the selections: session state
  const ScratchDir scratch;
  // fsync is the cost of each command; tmpfs makes the thousand cheap.
  const std::filesystem::path shm = "/dev/shm";
  const std::filesystem::path file =
      std::filesystem::is_directory(shm)
          ? shm / ("scanbench-property-" + std::to_string(::getpid()) + ".sbproj")
          : scratch / "p.sbproj";
  store::remove_project_files(file);
  store::Project project = store::Project::create(file);
  const std::int64_t scan = store_room(project);
  const std::int64_t baseline = project.history().back().id;
  const std::string initial = state_of(project);
  std::mt19937 random(2026);
  const auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(random); };
  int applied = 0, refused = 0;
  for (int k = 0; k < kOperations; ++k) {
    const std::vector<store::ObjectNode> nodes = project.object_nodes();
    const auto some_node = [&] {
      return nodes[static_cast<std::size_t>(pick(static_cast<int>(nodes.size())))].id;
    };
    try {
      switch (pick(nodes.empty() ? 4 : 12)) {
        case 0:
        case 1:
        case 2: {
          SelectSettings s =
              select_at(scan, pick(360) - 180.0, pick(90) - 60.0, static_cast<SelectMode>(pick(3)),
                        static_cast<segmentation::Channel>(pick(4)));
          tools.select(project, s);
          break;
        }
        case 3:
          if (pick(2))
            tools.commit(project, {scan, "object " + std::to_string(k), std::nullopt});
          else
            group_nodes(project, {"group " + std::to_string(k), std::nullopt, {}});
          break;
        case 4:
          group_nodes(project, {"group " + std::to_string(k), std::nullopt, {some_node()}});
          break;
        case 5:
          edit_node(project,
                    {some_node(), "renamed " + std::to_string(k), pick(2) == 0, std::nullopt, {}});
          break;
        case 6:
          edit_node(project, {some_node(),
                              std::nullopt,
                              std::nullopt,
                              std::optional<std::int64_t>(some_node()),
                              {}});
          break;
        case 7:
          delete_node(
              project,
              {some_node(), pick(2) ? DeletedPoints::kToPool : DeletedPoints::kDeleted, {}});
          break;
        case 9:
          separate_object(project, {some_node(), scan});
          break;
        case 11:
          if (pick(2)) {
            ungroup_node(project, some_node());
          } else {
            merge_objects(project, {{some_node(), some_node(), some_node()}});
          }
          break;
        case 10:
          if (pick(10) == 0) {  // a whole scan's proposals: now and then
            ProposeSettings s;
            s.scan_id = scan;
            s.proposals.min_pixels = 2000;
            propose_objects(project, s);
          }
          break;
        default:
          if (pick(2) && newest_done(project) > baseline) {
            project.undo();
          } else {
            project.redo();
          }
          break;
      }
      ++applied;
    } catch (const core::InputError&) {
      ++refused;  // a parent that is an object, a cycle, an empty selection: refused, unwritten
    }
    expect_consistent_tree(project, scan, k);
    if (HasFatalFailure() || HasFailure()) break;
  }
  EXPECT_GT(applied, kOperations * 7 / 10);
  while (newest_done(project) > baseline) ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(state_of(project), initial);
  store::remove_project_files(file);
  RecordProperty("refused", refused);
}

}  // namespace
}  // namespace scanbench::modeling
