// The level-of-detail store built from a project: it holds the shown model
// point for point, the same tree whatever the chunks and threads, and a
// build that fails leaves the store it would have replaced.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include "core/errors.hpp"
#include "modeling/lod/build_lod.hpp"
#include "modeling/lod/lod_store.hpp"
#include "modeling/lod_room_project.hpp"
#include "modeling/room_project.hpp"
#include "modeling/store/layer_store.hpp"
#include "support/test_support.hpp"

namespace scanbench::lod {
namespace {

using scanbench::test::ScratchDir;

TEST(LodStore, HoldsTheShownModelPointForPoint) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const LodRoomProject room = store_two_rooms(project);
  const LodBuildResult result = build_quietly(project);
  const test::RoomScan& truth = test::shared_room();

  std::size_t in_model = 0, merged_away = 0, deleted = 0;
  std::set<std::pair<std::int64_t, std::uint32_t>> expected;
  for (const std::int64_t id : {room.first, room.second}) {
    for (std::size_t i = 0; i < truth.scan.pixel_count(); ++i) {
      if (!acquisition::in_model(truth.scan, truth.geometry, i)) continue;
      ++in_model;
      if (id == room.second && room.keep[i] == 0) {
        ++merged_away;
      } else if (id == room.first && room.membership[i] == store::kDeletedPoints) {
        ++deleted;
      } else {
        expected.insert({id, static_cast<std::uint32_t>(i)});
      }
    }
  }
  EXPECT_EQ(result.in_model, in_model);
  EXPECT_EQ(result.merged_away, merged_away);
  EXPECT_EQ(result.deleted, deleted);
  EXPECT_EQ(result.points, expected.size());
  EXPECT_EQ(result.project_revision, project.revision());

  const LodStore store = LodStore::open(result.store);
  EXPECT_EQ(store.header().points, expected.size());
  EXPECT_EQ(store.header().project_revision, project.revision());
  ASSERT_EQ(store.scans().size(), 2u);
  std::map<std::uint16_t, acquisition::Scan> posed;  // the room at each store scan's pose
  for (const LodScan& scan : store.scans()) {
    posed[scan.index] = truth.scan;
    posed[scan.index].T_world_scan = scan.T_world_scan;
  }
  std::set<std::pair<std::int64_t, std::uint32_t>> found;
  float worst_m = 0.0f;
  for (const auto& [code, node] : read_store(store)) {
    const Eigen::AlignedBox3d box = store.header().cube.node_box(node.first.key);
    for (const LodPoint& p : node.second) {
      const LodScan& scan = store.scans().at(p.scan);
      EXPECT_TRUE(found.insert({scan.scan_id, p.pixel}).second) << "a pixel twice";
      const int row = static_cast<int>(p.pixel / 720), col = static_cast<int>(p.pixel % 720);
      const Eigen::Vector3d at = store.header().origin + box.min() +
                                 Eigen::Vector3d(p.offset[0], p.offset[1], p.offset[2]) * kQuantumM;
      worst_m = std::max(
          worst_m, static_cast<float>(
                       (at - acquisition::point_in_world(posed.at(p.scan), row, col)).norm()));
      const std::uint32_t owner = scan.scan_id == room.first ? room.membership[p.pixel] : 0u;
      EXPECT_EQ(p.object, owner);
      EXPECT_EQ(p.flags & LodPoint::kHasColor, LodPoint::kHasColor);
      EXPECT_EQ(p.rgb[0], truth.scan.rgb[3 * p.pixel]);
      EXPECT_EQ((p.flags & LodPoint::kHasNormal) != 0, truth.geometry.has_normal(p.pixel));
      EXPECT_TRUE(node.first.bounds.contains((at - store.header().origin).cast<float>()));
    }
    EXPECT_EQ(node.first.points, node.second.size());
  }
  EXPECT_EQ(found, expected);
  EXPECT_LE(worst_m, 1.8e-4f);  // a quantum on each axis
}

TEST(LodStore, IsTheSameTreeWhateverTheChunksAndThreads) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  store_two_rooms(project);
  LodBuildSettings whole;
  whole.output = dir / "whole.lod";
  whole.octree.max_leaf_points = 3000;
  whole.chunk_points = std::size_t{1} << 30;  // the whole model in one
  const LodBuildResult one = build_quietly(project, whole);
  EXPECT_EQ(one.chunks, 1u);
  LodBuildSettings cut = whole;
  cut.output = dir / "cut.lod";
  cut.chunk_points = 9000;
  cut.threads = 2;
  const LodBuildResult many = build_quietly(project, cut);
  EXPECT_GT(many.chunks, 4u);
  // In a memory limit that parks the points in a temporary file.
  LodBuildSettings parked = cut;
  parked.output = dir / "parked.lod";
  parked.memory_limit_bytes = 8'000'000;
  const LodBuildResult spilled = build_quietly(project, parked);
  // Chunks smaller than a leaf: the nodes above them still hold more.
  LodBuildSettings small = whole;
  small.output = dir / "small.lod";
  small.octree.max_leaf_points = 12000;
  small.chunk_points = 5000;
  const LodBuildResult small_chunks = build_quietly(project, small);
  small.output = dir / "small_whole.lod";
  small.chunk_points = std::size_t{1} << 30;
  const auto small_reference = read_store(LodStore::open(build_quietly(project, small).store));
  EXPECT_GT(small_chunks.chunks, 2u);
  EXPECT_EQ(read_store(LodStore::open(small_chunks.store)).size(), small_reference.size());
  // The chunk size the build chooses itself.
  LodBuildSettings automatic = whole;
  automatic.output = dir / "automatic.lod";
  automatic.chunk_points = 0;
  const LodBuildResult chosen = build_quietly(project, automatic);
  const auto a = read_store(LodStore::open(one.store));
  ASSERT_GT(a.size(), 10u);
  for (const LodBuildResult* other_build : {&many, &spilled, &chosen}) {
    const auto b = read_store(LodStore::open(other_build->store));
    ASSERT_EQ(a.size(), b.size());
    for (const auto& [code, node] : a) {
      ASSERT_TRUE(b.count(code)) << code;
      const auto& other = b.at(code);
      EXPECT_EQ(node.first.points_below, other.first.points_below);
      EXPECT_EQ(node.first.leaf, other.first.leaf);
      EXPECT_EQ(node.first.level_ends, other.first.level_ends);
      EXPECT_TRUE(node.second == other.second) << "node " << code;
    }
  }
}

// Cancels once the chunks are built: the new store's partial file exists.
class CancelAfterTheChunks : public core::Progress {
 public:
  void update(const core::ProgressStep& step) override {
    if (step.stage == "lod: build") request_cancel();
  }
};

TEST(LodStore, ACancelledBuildLeavesTheStoreItWouldHaveReplaced) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  store_two_rooms(project);
  const LodBuildResult first = build_quietly(project);
  const std::string before = test::read_file_bytes(first.store);
  CancelAfterTheChunks cancel;
  EXPECT_THROW(build_lod(project, {}, cancel), core::Cancelled);
  EXPECT_EQ(test::read_file_bytes(first.store), before);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
  }
  // A crashed build's file (a process long gone) is removed by the next build.
  std::ofstream(first.store.string() + ".partial-999999999") << "half a store";
  build_quietly(project);
  EXPECT_FALSE(std::filesystem::exists(first.store.string() + ".partial-999999999"));
  EXPECT_EQ(LodStore::open(first.store).header().points, first.points);
}

// A build killed at any moment (SIGKILL: no destructor runs) leaves the
// store it would have replaced, byte for byte, or the new one whole; never
// a mix. The next build clears what the dead ones left.
TEST(LodStore, ABuildKilledAtAnyMomentLeavesTheOldStoreOrTheNew) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const LodRoomProject room = store_two_rooms(project);
  const LodBuildResult old_build = build_quietly(project);
  const std::string old_bytes = test::read_file_bytes(old_build.store);
  {  // the project moves on: a new store would hold other points
    std::vector<std::uint8_t> keep = room.keep;
    for (std::size_t i = 0; i < keep.size(); i += 2) keep[i] = 1;
    store::Project::Edit edit = project.begin_command("merge", "{}");
    project.put_layer(
        edit, room.second,
        store::encode_layer<std::uint8_t>(store::layer::kKeep, store::ElementType::kU8, keep));
    edit.commit("{}");
  }
  LodBuildSettings to_the_side;
  to_the_side.output = dir / "new.lod";
  const auto start = std::chrono::steady_clock::now();
  const LodBuildResult new_build = build_quietly(project, to_the_side);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_NE(new_build.points, old_build.points);
  const auto new_nodes = read_store(LodStore::open(new_build.store));
  std::mt19937 random(29);
  std::uniform_real_distribution<double> moment(0.0, 2.0 * build_s);
  std::size_t old_seen = 0, new_seen = 0;
  constexpr int kAttempts = 5;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    if (attempt > 0 && test::read_file_bytes(old_build.store) != old_bytes) {
      // The last kill came after the rename: put the old store back.
      std::ofstream(old_build.store, std::ios::binary | std::ios::trunc) << old_bytes;
    }
    // The last one is let finish: the new store, before the next build.
    run_in_child([&] { build_quietly(store::Project::open_for_reading(dir / "p.sbproj")); },
                 attempt + 1 < kAttempts ? std::optional(moment(random)) : std::nullopt);
    const std::string bytes = test::read_file_bytes(old_build.store);
    if (bytes == old_bytes) {
      ++old_seen;
      continue;
    }
    const LodStore now = LodStore::open(old_build.store);  // whole, or this throws
    EXPECT_EQ(now.header().points, new_build.points);
    const auto nodes = read_store(now);
    ASSERT_EQ(nodes.size(), new_nodes.size());
    for (const auto& [code, node] : nodes) {
      ASSERT_TRUE(new_nodes.count(code)) << code;
      EXPECT_EQ(node.first.level_ends, new_nodes.at(code).first.level_ends);
      EXPECT_TRUE(node.second == new_nodes.at(code).second) << "node " << code;
    }
    ++new_seen;
  }
  EXPECT_GT(old_seen, 0u);
  EXPECT_GT(new_seen, 0u);
  std::printf("killed builds: %zu left the old store, %zu the new one\n", old_seen, new_seen);
  build_quietly(project);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
  }
}

TEST(LodStore, RefusesWhatIsNotAStoreNamingTheFile) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const auto refused = [](const std::filesystem::path& file, const std::string& words) {
    try {
      LodStore::open(file);
      ADD_FAILURE() << file << " opened";
    } catch (const core::FileError& e) {
      EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused(dir / "missing.lod", "scanbench lod");
  refused(dir / "p.sbproj", "not a scanbench level-of-detail store");
  std::ofstream(dir / "garbage.lod") << "this is not an SQLite file at all, not even close";
  refused(dir / "garbage.lod", "garbage.lod");
  // A scan without geometry: refused before anything is written.
  test::insert_committed(project, test::shared_room().scan);
  core::Progress quiet;
  EXPECT_THROW(build_lod(project, {}, quiet), core::InputError);
  EXPECT_FALSE(std::filesystem::exists(LodStore::path_for(project.path())));
}

// The room's store with `sql` run on a copy, checks off: what opening it or
// reading its nodes says.
std::string refusal_after(const std::string& sql) {
  const scanbench::test::ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  modeling::store_room(project);
  const LodBuildResult result = build_quietly(project);
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(result.store.c_str(), &db), SQLITE_OK);
  const std::string unchecked = "PRAGMA ignore_check_constraints = 1; " + sql;
  EXPECT_EQ(sqlite3_exec(db, unchecked.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
  sqlite3_close(db);
  try {
    const LodStore store = LodStore::open(result.store);
    for (const LodNodeInfo& node : store.nodes()) store.read_points(node.key);
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.sbproj.lod"), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "read after " << sql;
  return "";
}

TEST(LodStore, ADamagedDescriptionIsRefusedNamingWhatIsDamaged) {
  EXPECT_NE(refusal_after("UPDATE lod_header SET format = 99").find("newer"), std::string::npos);
  EXPECT_NE(refusal_after("UPDATE lod_header SET edge_bits = 40").find("header"),
            std::string::npos);
  EXPECT_NE(refusal_after("DELETE FROM lod_header").find("never completed"), std::string::npos);
  EXPECT_NE(refusal_after("UPDATE lod_scans SET pose = zeroblob(8)").find("scan"),
            std::string::npos);
  EXPECT_NE(refusal_after("UPDATE lod_nodes SET code = 4611686018427387904 WHERE code = 1")
                .find("damaged code"),
            std::string::npos);
  EXPECT_NE(refusal_after("UPDATE lod_nodes SET level_ends = zeroblob(36) WHERE code = 1")
                .find("damaged description"),
            std::string::npos);
  EXPECT_NE(refusal_after("UPDATE lod_nodes SET points = 4000000000 WHERE code = 1")
                .find("node 1 (depth 0)"),
            std::string::npos);
}

TEST(LodStore, AModelWithoutShownPointsHasAStoreWithoutNodes) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t id = modeling::store_room(project);
  store::Project::Edit edit = project.begin_command("segment", "{}");
  const std::vector<std::uint32_t> deleted(test::shared_room().scan.pixel_count(),
                                           store::kDeletedPoints);
  project.put_layer(edit, id,
                    store::encode_layer<std::uint32_t>(store::layer::kMembership,
                                                       store::ElementType::kU32, deleted));
  edit.commit("{}");
  const LodBuildResult result = build_quietly(project);
  EXPECT_EQ(result.points, 0u);
  EXPECT_GT(result.deleted, 0u);
  const LodStore store = LodStore::open(result.store);
  EXPECT_TRUE(store.nodes().empty());
  EXPECT_EQ(store.header().points, 0u);
}

TEST(LodStore, ADamagedNodeIsReportedByName) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  modeling::store_room(project);
  const LodBuildResult result = build_quietly(project);
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(result.store.c_str(), &db), SQLITE_OK);
    EXPECT_EQ(sqlite3_exec(db, "UPDATE lod_nodes SET data = zeroblob(length(data)) WHERE code = 1",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  const LodStore store = LodStore::open(result.store);
  try {
    store.read_points(NodeKey{});
    ADD_FAILURE() << "a damaged node read";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("node 1 (depth 0)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("p.sbproj.lod"), std::string::npos) << e.what();
  }
  // The other nodes still read.
  for (const LodNodeInfo& info : store.nodes()) {
    if (info.key.depth > 0) {
      EXPECT_EQ(store.read_points(info.key).size(), info.points);
    }
  }
}

}  // namespace
}  // namespace scanbench::lod
