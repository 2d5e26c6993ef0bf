// The level-of-detail store updated in place (modeling/lod/update_lod.hpp):
// after any sequence of commands, undos and redos it is, node for node, the
// store a build from scratch gives; a killed update leaves the old store or
// the new one.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <random>

#include "modeling/lod/update_lod.hpp"
#include "modeling/lod_room_project.hpp"

namespace scanbench::lod {
namespace {

using scanbench::test::ScratchDir;

using StoreNodes = std::map<std::uint64_t, std::pair<LodNodeInfo, std::vector<LodPoint>>>;

// Whether two stores hold the same nodes, each with the same description
// and points; says where they differ first.
::testing::AssertionResult same_nodes(const StoreNodes& a, const StoreNodes& b) {
  if (a.size() != b.size())
    return ::testing::AssertionFailure() << a.size() << " nodes against " << b.size();
  for (const auto& [code, node] : a) {
    const auto other = b.find(code);
    if (other == b.end()) return ::testing::AssertionFailure() << "node " << code << " only in one";
    const LodNodeInfo &x = node.first, &y = other->second.first;
    if (x.leaf != y.leaf || x.points_below != y.points_below || x.level_ends != y.level_ends ||
        !x.bounds.isApprox(y.bounds) || x.max_radius_m != y.max_radius_m) {
      return ::testing::AssertionFailure() << "node " << code << "'s description differs";
    }
    if (node.second != other->second.second)
      return ::testing::AssertionFailure() << "node " << code << "'s points differ";
  }
  return ::testing::AssertionSuccess();
}

// Every row of `table` in the store `file`, as text.
std::vector<std::string> table_rows(const std::filesystem::path& file, const std::string& table) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  std::vector<std::string> rows;
  const std::string sql = "SELECT * FROM " + table + " ORDER BY 1, 2";
  sqlite3_stmt* statement = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &statement, nullptr), SQLITE_OK);
  while (sqlite3_step(statement) == SQLITE_ROW) {
    std::string row;
    for (int c = 0; c < sqlite3_column_count(statement); ++c) {
      const auto* bytes = static_cast<const char*>(sqlite3_column_blob(statement, c));
      row.append(bytes, static_cast<std::size_t>(sqlite3_column_bytes(statement, c))) += '|';
    }
    rows.push_back(std::move(row));
  }
  sqlite3_finalize(statement);
  sqlite3_close(db);
  return rows;
}

// Whether two stores hold the same pixel digests and node tiles.
void expect_same_digests(const std::filesystem::path& a, const std::filesystem::path& b,
                         std::size_t step) {
  for (const char* table : {"lod_pixels", "lod_node_tiles"})
    EXPECT_TRUE(table_rows(a, table) == table_rows(b, table)) << table << ", step " << step;
}

// Every point of a store by its scan id and pixel: where it lies (in
// quanta from the store's origin) and the rest of what the store keeps.
std::map<std::pair<std::int64_t, std::uint32_t>, std::pair<std::array<std::int64_t, 3>, LodPoint>>
world_points(const LodStore& store) {
  std::map<std::pair<std::int64_t, std::uint32_t>, std::pair<std::array<std::int64_t, 3>, LodPoint>>
      points;
  const OctreeCube& cube = store.header().cube;
  for (const auto& [code, node] : read_store(store)) {
    const std::array<std::uint64_t, 3> corner = cube.node_corner(node.first.key);
    for (LodPoint p : node.second) {
      std::array<std::int64_t, 3> at{};
      for (int a = 0; a < 3; ++a)
        at[a] = cube.corner[a] + static_cast<std::int64_t>(corner[a] + p.offset[a]);
      p.offset = {};
      points[{store.scans().at(p.scan).scan_id, p.pixel}] = {at, p};
    }
  }
  return points;
}

// Writes `values` as scan `id`'s layer `name` in a command `command`.
template <typename T>
void write_layer(store::Project& project, const char* command, std::int64_t id, const char* name,
                 store::ElementType type, const std::vector<T>& values) {
  store::Project::Edit edit = project.begin_command(command, "{}");
  project.put_layer(edit, id, store::encode_layer<T>(name, type, values));
  edit.commit("{}");
}

// Settings for a deep tree (edits split and join leaves), one thread.
LodBuildSettings deep_tree() {
  LodBuildSettings settings;
  settings.threads = 1;
  settings.octree.max_leaf_points = 2000;
  return settings;
}

// A random rectangle of the room's 720-column grid.
std::vector<std::size_t> random_rectangle(std::mt19937& random, std::size_t pixels) {
  constexpr std::size_t kColumns = 720;
  const std::size_t rows = pixels / kColumns;
  std::uniform_int_distribution<std::size_t> row(0, rows - 1), column(0, kColumns - 1);
  const std::size_t r0 = row(random), c0 = column(random);
  const std::size_t r1 = std::min(rows, r0 + 1 + row(random) / 2);
  const std::size_t c1 = std::min(kColumns, c0 + 1 + column(random) / 2);
  std::vector<std::size_t> inside;
  for (std::size_t r = r0; r < r1; ++r) {
    for (std::size_t c = c0; c < c1; ++c) inside.push_back(r * kColumns + c);
  }
  return inside;
}

TEST(LodUpdate, RandomCommandSequencesGiveTheStoreABuildFromScratchGives) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  LodRoomProject room = store_two_rooms(project);
  const LodBuildSettings settings = deep_tree();
  build_quietly(project, settings);
  LodBuildSettings from_scratch = settings;
  from_scratch.output = dir / "scratch.lod";
  // Updates on two workers, builds on one: the store must not depend on it.
  LodBuildSettings updating = settings;
  updating.threads = 2;
  const std::size_t pixels = test::shared_room().scan.pixel_count();

  std::mt19937 random(2029);
  core::Progress quiet;
  std::uint64_t added = 0, removed = 0, relabelled = 0, undone = 0;
  // Commits (0), deletes (1), merges (2), undos (3) and redos (4) of
  // random rectangles of pixels.
  const std::array<int, 11> script = {0, 1, 2, 3, 3, 4, 0, 1, 3, 4, 2};
  for (std::size_t step = 0; step < script.size(); ++step) {
    const int kind = script[step];
    if (kind == 0 || kind == 1) {  // a commit into an object, or a delete
      std::vector<std::uint32_t>& owners = room.membership;
      const std::uint32_t object =
          kind == 1 ? store::kDeletedPoints : 1 + static_cast<std::uint32_t>(random() % 6);
      for (const std::size_t i : random_rectangle(random, pixels)) owners[i] = object;
      write_layer(project, kind == 1 ? "delete" : "commit", room.first, store::layer::kMembership,
                  store::ElementType::kU32, owners);
    } else if (kind == 2) {  // a merge keeping other pixels of the second scan
      for (const std::size_t i : random_rectangle(random, pixels)) room.keep[i] ^= 1;
      write_layer(project, "merge", room.second, store::layer::kKeep, store::ElementType::kU8,
                  room.keep);
    } else if (kind == 3) {
      if (project.undo()) ++undone;
    } else {
      project.redo();
    }
    std::string why_not;
    const std::optional<LodUpdateResult> update = update_lod(project, updating, quiet, why_not);
    ASSERT_TRUE(update) << "step " << step << ": " << why_not;
    EXPECT_EQ(update->project_revision, project.revision());
    added += update->points_added;
    removed += update->points_removed;
    relabelled += update->points_relabelled;
    const LodStore updated = LodStore::open(update->store);
    const LodStore scratch = LodStore::open(build_quietly(project, from_scratch).store);
    EXPECT_EQ(updated.header().points, scratch.header().points) << "step " << step;
    EXPECT_EQ(updated.header().nodes, scratch.header().nodes) << "step " << step;
    EXPECT_EQ(updated.header().project_revision, project.revision());
    ASSERT_TRUE(same_nodes(read_store(updated), read_store(scratch))) << "step " << step;
    expect_same_digests(update->store, from_scratch.output, step);
  }
  EXPECT_GT(added, 0u);
  EXPECT_GT(removed, 0u);
  EXPECT_GT(relabelled, 0u);
  EXPECT_GT(undone, 0u);

  // The geometry stage run again writes the same values: still in place.
  {
    store::Project::Edit edit = project.begin_command("geometry", "{}");
    for (const store::EncodedLayer& layer : store::encode_geometry(test::shared_room().geometry))
      project.put_layer(edit, room.first, layer);
    edit.commit("{}");
    std::string why_not;
    const std::optional<LodUpdateResult> same = update_lod(project, settings, quiet, why_not);
    ASSERT_TRUE(same) << why_not;
    EXPECT_EQ(same->nodes_written, 0u);
  }

  // A new scan from the first station (inside the store's cube): inserted.
  acquisition::Scan again = test::shared_room().scan;
  const std::int64_t third = test::insert_committed(project, again);
  {
    store::Project::Edit edit = project.begin_command("geometry", "{}");
    for (const store::EncodedLayer& layer : store::encode_geometry(test::shared_room().geometry))
      project.put_layer(edit, third, layer);
    edit.commit("{}");
  }
  std::string why_not;
  const std::optional<LodUpdateResult> inserted = update_lod(project, settings, quiet, why_not);
  ASSERT_TRUE(inserted) << why_not;
  EXPECT_EQ(inserted->scans_added, 1u);
  EXPECT_GT(inserted->points_added, 100000u);
  const LodStore updated = LodStore::open(inserted->store);
  ASSERT_EQ(updated.scans().size(), 3u);
  EXPECT_TRUE(same_nodes(read_store(updated),
                         read_store(LodStore::open(build_quietly(project, from_scratch).store))));
  expect_same_digests(inserted->store, from_scratch.output, script.size());

  // A new pose: the scan's points move in place. The grown bounds give a
  // build from scratch another cube, so the two are compared point for point.
  {
    store::Project::Edit edit = project.begin_command("register", "{}");
    acquisition::Scan moved = again;
    moved.T_world_scan.translation().x() += 0.01;
    project.set_pose(edit, third, moved);
    edit.commit("{}");
  }
  const std::optional<LodUpdateResult> moved = update_lod(project, settings, quiet, why_not);
  ASSERT_TRUE(moved) << why_not;
  EXPECT_EQ(moved->points_added, moved->points_removed);
  EXPECT_GT(moved->points_added, 100000u);
  EXPECT_EQ(world_points(LodStore::open(moved->store)),
            world_points(LodStore::open(build_quietly(project, from_scratch).store)));

  // Most of the model moving is built again, and says why.
  {
    store::Project::Edit edit = project.begin_command("register", "{}");
    for (const store::StoredScanSummary& scan : project.scans()) {
      acquisition::Scan shifted = test::shared_room().scan;
      shifted.T_world_scan = scan.summary.T_world_scan;
      shifted.T_world_scan.translation().y() += 0.02;
      project.set_pose(edit, scan.id, shifted);
    }
    edit.commit("{}");
  }
  EXPECT_FALSE(update_lod(project, settings, quiet, why_not));
  EXPECT_NE(why_not.find("new poses"), std::string::npos) << why_not;
  const LodRefreshResult rebuilt = refresh_lod(project, settings, quiet);
  EXPECT_TRUE(rebuilt.built);
  EXPECT_EQ(rebuilt.why_built, why_not);
}

// Kills updates with SIGKILL at random moments: each leaves the store as
// it was or as the update makes it, node for node; the next update (or
// read) finds it whole.
TEST(LodUpdate, AnUpdateKilledAtAnyMomentLeavesTheOldStoreOrTheNew) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  LodRoomProject room = store_two_rooms(project);
  const LodBuildSettings settings = deep_tree();
  const std::filesystem::path file = build_quietly(project, settings).store;
  const std::filesystem::path kept = dir / "old.lod";
  std::filesystem::copy_file(file, kept);
  const StoreNodes old_nodes = read_store(LodStore::open(file));
  // Half the first scan into an object, a band of it deleted.
  for (std::size_t i = 0; i < room.membership.size() / 2; ++i) room.membership[i] = 4;
  for (std::size_t i = 0; i < 720 * 40; ++i) room.membership[i] = store::kDeletedPoints;
  write_layer(project, "commit", room.first, store::layer::kMembership, store::ElementType::kU32,
              room.membership);
  LodBuildSettings to_the_side = settings;
  to_the_side.output = dir / "new.lod";
  const StoreNodes new_nodes =
      read_store(LodStore::open(build_quietly(project, to_the_side).store));

  core::Progress quiet;
  const auto start = std::chrono::steady_clock::now();
  {
    std::string why_not;
    ASSERT_TRUE(update_lod(project, settings, quiet, why_not)) << why_not;
  }
  const double update_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::mt19937 random(31);
  std::uniform_real_distribution<double> moment(0.0, 2.0 * update_s);
  std::size_t old_seen = 0, new_seen = 0;
  constexpr int kAttempts = 8;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    std::filesystem::copy_file(kept, file, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::remove(file.string() + "-journal");
    // The last one is let finish.
    run_in_child(
        [&] {
          core::Progress silent;
          std::string ignored;
          update_lod(store::Project::open_for_reading(dir / "p.sbproj"), settings, silent, ignored);
        },
        attempt + 1 < kAttempts ? std::optional(moment(random)) : std::nullopt);
    const LodStore now = LodStore::open(file);  // rolls back what a killed update left
    const StoreNodes nodes = read_store(now);
    if (now.header().project_revision == project.revision()) {
      EXPECT_TRUE(same_nodes(nodes, new_nodes));
      ++new_seen;
    } else {
      EXPECT_TRUE(same_nodes(nodes, old_nodes));
      ++old_seen;
    }
  }
  std::printf("killed updates: %zu left the old store, %zu the new one\n", old_seen, new_seen);
  EXPECT_GT(old_seen, 0u);
  EXPECT_GT(new_seen, 0u);
}

}  // namespace
}  // namespace scanbench::lod
