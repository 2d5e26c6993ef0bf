// The object tree's store: node versions written by commands, read back as
// the newest done command left them, undone and redone across processes,
// and checked like every record.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vector>

#include "core/errors.hpp"
#include "modeling/store/project.hpp"
#include "project_test_support.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;
using ::testing::HasSubstr;

store::ObjectNode group(std::int64_t id, std::string name) {
  store::ObjectNode node;
  node.id = id;
  node.name = std::move(name);
  node.kind = store::NodeKind::kGroup;
  return node;
}

store::ObjectNode wall(std::int64_t id, std::int64_t parent) {
  store::ObjectNode node;
  node.id = id;
  node.name = "wall south";
  node.parent = parent;
  node.points = 1234;
  node.mean_footprint_m = 0.0125;
  // Georeferenced: far from the origin, and -0.0 kept as such.
  node.bbox_world = Eigen::AlignedBox3d(Eigen::Vector3d(637012.24, 849028.5, -0.0),
                                        Eigen::Vector3d(637030.75, 849029.25, 12.5));
  return node;
}

void expect_same(const store::ObjectNode& a, const store::ObjectNode& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.parent, b.parent);
  EXPECT_EQ(a.hidden, b.hidden);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.mean_footprint_m, b.mean_footprint_m);
  ASSERT_EQ(a.bbox_world.has_value(), b.bbox_world.has_value());
  if (a.bbox_world) {
    EXPECT_EQ(a.bbox_world->min(), b.bbox_world->min());
    EXPECT_EQ(a.bbox_world->max(), b.bbox_world->max());
    EXPECT_EQ(std::signbit(a.bbox_world->min().z()), std::signbit(b.bbox_world->min().z()));
  }
}

// Commits a command that writes `nodes`.
void commit_nodes(store::Project& project, const std::vector<store::ObjectNode>& nodes) {
  store::Project::Edit edit = project.begin_command("objects", "{}");
  for (const store::ObjectNode& node : nodes) project.put_node(edit, node);
  edit.commit("{}");
}

TEST(ObjectNodes, NodesReadBackBitForBitAcrossReopen) {
  const ScratchDir dir;
  {
    store::Project project = store::Project::create(dir / "p.sbproj");
    EXPECT_TRUE(project.object_nodes().empty());
    EXPECT_EQ(project.new_node_id(), 1);
    commit_nodes(project, {group(1, "north hall"), wall(2, 1)});
    EXPECT_EQ(project.new_node_id(), 3);
  }
  const store::Project project = store::Project::open(dir / "p.sbproj");
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  ASSERT_EQ(nodes.size(), 2u);
  expect_same(nodes[0], group(1, "north hall"));
  expect_same(nodes[1], wall(2, 1));
}

TEST(ObjectNodes, ChangesAndDeletionsAreUndoneAndRedoneAcrossProcesses) {
  const ScratchDir dir;
  {
    store::Project project = store::Project::create(dir / "p.sbproj");
    commit_nodes(project, {group(1, "north hall"), wall(2, 1)});
    store::ObjectNode renamed = wall(2, 1);
    renamed.name = "wall west";
    renamed.hidden = true;
    commit_nodes(project, {renamed});
    store::Project::Edit edit = project.begin_command("delete", "{}");
    project.remove_node(edit, 1);
    project.remove_node(edit, 99);  // no such node: nothing happens
    edit.commit("{}");
    ASSERT_EQ(project.object_nodes().size(), 1u);
    EXPECT_EQ(project.object_nodes()[0].name, "wall west");
  }
  {
    store::Project project = store::Project::open(dir / "p.sbproj");
    ASSERT_TRUE(project.undo().has_value());  // the deletion
    ASSERT_EQ(project.object_nodes().size(), 2u);
    ASSERT_TRUE(project.undo().has_value());  // the rename
    expect_same(project.object_nodes()[1], wall(2, 1));
  }
  store::Project project = store::Project::open(dir / "p.sbproj");
  ASSERT_TRUE(project.redo().has_value());
  EXPECT_EQ(project.object_nodes()[1].name, "wall west");
  EXPECT_TRUE(project.object_nodes()[1].hidden);
  ASSERT_TRUE(project.undo().has_value());
  ASSERT_TRUE(project.undo().has_value());  // the creation
  EXPECT_TRUE(project.object_nodes().empty());
}

TEST(ObjectNodes, ANewCommandDiscardsTheUndoneNodeVersions) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  commit_nodes(project, {group(1, "site")});
  commit_nodes(project, {group(2, "north hall")});
  ASSERT_TRUE(project.undo().has_value());
  commit_nodes(project, {group(2, "keller hall")});
  ASSERT_EQ(project.object_nodes().size(), 2u);
  EXPECT_EQ(project.object_nodes()[1].name, "keller hall");
  EXPECT_FALSE(project.redo().has_value());
  test::RawDatabase raw(dir / "p.sbproj");
  EXPECT_EQ(raw.text("SELECT count(*) FROM object_nodes"), "2");
}

TEST(ObjectNodes, ADamagedNodeRowIsFoundByCheckAndRefusedWhenRead) {
  const ScratchDir dir;
  {
    store::Project project = store::Project::create(dir / "p.sbproj");
    commit_nodes(project, {group(1, "north hall"), wall(2, 1)});
  }
  {
    test::RawDatabase raw(dir / "p.sbproj");
    raw.execute("UPDATE object_nodes SET points = 4321 WHERE node_id = 2");
  }
  const store::Project project = store::Project::open(dir / "p.sbproj");
  const store::Project::CheckReport report = project.check();
  ASSERT_EQ(report.damage.size(), 1u);
  EXPECT_THAT(report.damage[0], HasSubstr("object node 2"));
  try {
    static_cast<void>(project.object_nodes());
    FAIL() << "a damaged node was read";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("object node 2"));
  }
}

// The tree a connection keeps between commands follows its own commits,
// and is read again after another process's commit, an undo, a refused
// edit and a rolled-back batch (whose revision another process may reach
// again with another tree).
TEST(ObjectNodes, TheTreeAConnectionKeepsIsNeverStale) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  store::Project mine = store::Project::create(file);
  commit_nodes(mine, {group(1, "site")});
  ASSERT_EQ(mine.nodes_named("site"), std::vector<std::int64_t>{1});
  commit_nodes(mine, {group(1, "campus")});  // followed from the commit itself
  EXPECT_EQ(mine.nodes_named("campus"), std::vector<std::int64_t>{1});
  store::Project other = store::Project::open(file);
  commit_nodes(other, {group(1, "north campus")});
  EXPECT_EQ(mine.object_nodes().front().name, "north campus");
  ASSERT_TRUE(mine.undo());
  EXPECT_EQ(mine.object_nodes().front().name, "campus");
  {
    store::Project::Edit refused = mine.begin_command("objects", "{}");
    mine.put_node(refused, group(1, "refused"));
  }  // rolled back
  EXPECT_EQ(mine.object_nodes().front().name, "campus");
  const std::int64_t revision = mine.revision();
  {
    store::Project::Batch batch = mine.begin_batch();
    commit_nodes(mine, {group(1, "in the batch")});
    EXPECT_EQ(mine.object_nodes().front().name, "in the batch");
  }  // rolled back: the revision goes back
  EXPECT_EQ(mine.revision(), revision);
  commit_nodes(other, {group(1, "the other's")});
  EXPECT_EQ(mine.revision(), revision + 1);
  EXPECT_EQ(mine.object_nodes().front().name, "the other's");
}

}  // namespace
}  // namespace scanbench::modeling
