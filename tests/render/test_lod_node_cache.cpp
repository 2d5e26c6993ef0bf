// The nodes of a level-of-detail store in memory: a loader thread reads
// what the frame asks for, the cache keeps what was drawn last within its
// byte limit, and a damaged node is reported and never asked for again.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <numeric>

#include "render/lod_node_cache.hpp"
#include "render/lod_room_store.hpp"

namespace scanbench::render {
namespace {

std::vector<lod::NodeKey> keys_of(const LodHierarchy& h) {
  std::vector<lod::NodeKey> keys;
  for (const lod::LodNodeInfo& node : h.nodes) keys.push_back(node.key);
  return keys;
}

std::vector<std::size_t> every_node(const LodHierarchy& h) {
  std::vector<std::size_t> all(h.nodes.size());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

TEST(LodNodeCache, LoadsWhatTheFrameAsksForAsTheStoreHoldsIt) {
  const LodRoomStore& room = lod_room_store();
  LodNodeCache cache(room.store, keys_of(room.hierarchy), std::uint64_t{1} << 30);
  EXPECT_FALSE(cache.loaded(0));
  cache.request(every_node(room.hierarchy));
  cache.wait_idle();
  const std::vector<std::size_t> taken = cache.collect({});
  EXPECT_EQ(taken.size(), room.hierarchy.nodes.size());
  const lod::LodStore store = lod::LodStore::open(room.store);
  std::uint64_t bytes = 0;
  for (std::size_t k = 0; k < room.hierarchy.nodes.size(); ++k) {
    ASSERT_TRUE(cache.loaded(k)) << k;
    const std::span<const lod::LodPoint> points = cache.points(k);
    const std::vector<lod::LodPoint> stored = store.read_points(room.hierarchy.nodes[k].key);
    EXPECT_TRUE(std::equal(points.begin(), points.end(), stored.begin(), stored.end())) << k;
    bytes += points.size_bytes();
  }
  EXPECT_EQ(cache.bytes(), bytes);
  EXPECT_TRUE(cache.failures().empty());
  EXPECT_FALSE(cache.busy());
}

TEST(LodNodeCache, KeepsWhatWasDrawnLastWithinItsLimit) {
  const LodRoomStore& room = lod_room_store();
  const std::uint64_t root_bytes = room.hierarchy.nodes[0].points * sizeof(lod::LodPoint);
  LodNodeCache cache(room.store, keys_of(room.hierarchy), 2 * root_bytes);
  cache.request(every_node(room.hierarchy));
  cache.wait_idle();
  const std::vector<std::size_t> in_use{0};
  cache.collect(in_use);
  EXPECT_LE(cache.bytes(), 2 * root_bytes);
  EXPECT_TRUE(cache.loaded(0));  // drawn last: kept
  EXPECT_GT(cache.peak_bytes(), cache.bytes());
  // What is let go comes back when asked for again.
  std::size_t gone = 1;
  while (cache.loaded(gone)) ++gone;
  cache.request({gone});
  cache.wait_idle();
  cache.collect(std::vector<std::size_t>{gone});
  EXPECT_TRUE(cache.loaded(gone));
}

TEST(LodNodeCache, ADamagedNodeIsReportedAndNotAskedForAgain) {
  const LodRoomStore& room = lod_room_store();
  const scanbench::test::ScratchDir dir;
  const std::filesystem::path copy = dir / "damaged.lod";
  std::filesystem::copy_file(room.store, copy);
  const lod::NodeKey broken = room.hierarchy.nodes[1].key;
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(copy.c_str(), &db), SQLITE_OK);
    const std::string sql =
        "UPDATE lod_nodes SET data = zeroblob(16) WHERE code = " + std::to_string(broken.code());
    EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
  }
  LodNodeCache cache(copy, keys_of(room.hierarchy), std::uint64_t{1} << 30);
  cache.request({0, 1, 2});
  cache.wait_idle();
  cache.collect({});
  EXPECT_TRUE(cache.loaded(0));
  EXPECT_FALSE(cache.loaded(1));
  EXPECT_TRUE(cache.loaded(2));
  ASSERT_EQ(cache.failures().size(), 1u);
  EXPECT_EQ(cache.failures()[0].first, 1u);
  EXPECT_NE(cache.failures()[0].second.find("damaged.lod"), std::string::npos)
      << cache.failures()[0].second;
  cache.request({1});
  EXPECT_FALSE(cache.busy());
}

}  // namespace
}  // namespace scanbench::render
