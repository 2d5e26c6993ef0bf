// What the level-of-detail store's reader and writer share: its SQLite
// identity and schema, and how both name what they find damaged. Internal
// to modeling/lod/.
#pragma once

#include <sqlite3.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "modeling/lod/lod_store.hpp"
#include "modeling/lod/octree_cube.hpp"
#include "modeling/lod/octree_sampling.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::lod::schema {

// "SBLD" in the header's application_id: a store, not a project or another
// application's database.
inline constexpr std::uint32_t kLodApplicationId = 0x53424c44;
// Node data is read far more often than written: zstd's fastest level
// compresses 40-byte points about 2× and decodes at memory speed.
inline constexpr int kNodeCompressionLevel = 1;

inline constexpr const char* kSchema = R"sql(
CREATE TABLE lod_header (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  format INTEGER NOT NULL,
  project_revision INTEGER NOT NULL,
  origin_x REAL NOT NULL, origin_y REAL NOT NULL, origin_z REAL NOT NULL,
  corner_x INTEGER NOT NULL, corner_y INTEGER NOT NULL, corner_z INTEGER NOT NULL,
  edge_bits INTEGER NOT NULL CHECK (edge_bits BETWEEN 7 AND 32),
  max_leaf_points INTEGER NOT NULL CHECK (max_leaf_points >= 1),
  points INTEGER NOT NULL,
  nodes INTEGER NOT NULL);
CREATE TABLE lod_scans (
  point_scan INTEGER PRIMARY KEY CHECK (point_scan BETWEEN 0 AND 65535),
  scan_id INTEGER NOT NULL UNIQUE,
  name TEXT NOT NULL,
  intensity_low REAL NOT NULL,
  intensity_high REAL NOT NULL,
  pose BLOB NOT NULL CHECK (length(pose) = 128),
  source TEXT NOT NULL,
  owners_source TEXT NOT NULL,
  content TEXT NOT NULL,
  digest_rows INTEGER NOT NULL CHECK (digest_rows >= 1),
  columns INTEGER NOT NULL CHECK (columns >= 0));
CREATE TABLE lod_pixels (
  point_scan INTEGER NOT NULL REFERENCES lod_scans (point_scan),
  band INTEGER NOT NULL CHECK (band >= 0),
  owners BLOB NOT NULL,
  PRIMARY KEY (point_scan, band));
CREATE TABLE lod_nodes (
  code INTEGER PRIMARY KEY CHECK (code >= 1),
  leaf INTEGER NOT NULL CHECK (leaf IN (0, 1)),
  points_below INTEGER NOT NULL,
  points INTEGER NOT NULL CHECK (points >= 0 AND points <= points_below),
  level_ends BLOB NOT NULL CHECK (length(level_ends) = 36),
  bounds BLOB NOT NULL CHECK (length(bounds) = 24),
  max_radius REAL NOT NULL,
  data BLOB NOT NULL);
CREATE TABLE lod_node_tiles (
  code INTEGER PRIMARY KEY REFERENCES lod_nodes (code),
  count INTEGER NOT NULL CHECK (count >= 0),
  tiles BLOB NOT NULL);
)sql";

template <typename T>
std::span<const std::uint8_t> bytes_of(const T* data, std::size_t count) {
  return {reinterpret_cast<const std::uint8_t*>(data), count * sizeof(T)};
}

// Throws core::InputError: `where` in the store `file` is damaged as
// `problem` says.
[[noreturn]] inline void damaged(const std::filesystem::path& file, const std::string& where,
                                 const std::string& problem) {
  core::FilePosition position;
  position.detail = where;
  throw core::InputError(file.string(), position, problem);
}

// A connection that waits up to 30 s for another's write (an update) to end.
inline sqlite3* connect(const std::filesystem::path& file, int flags) {
  sqlite3* db =
      store::sqlite::open_connection(file.string(), flags, "opening the level-of-detail store");
  sqlite3_busy_timeout(db, 30000);
  return db;
}

// A node as its rows hold it: its points compressed, with its bounds,
// largest radius and the scan tiles its points come from (tile_of).
// Encoding takes no connection, so threads encode while one writes.
struct EncodedNode {
  NodeKey key;
  bool leaf = false;
  std::uint64_t points_below = 0;
  std::uint64_t points = 0;
  std::array<std::uint32_t, kNodeLevels> level_ends{};
  std::array<float, 6> bounds{};  // min, max; zeros without points
  float max_radius = 0.0f;
  std::vector<std::uint8_t> data;   // the points, a zstd frame
  std::uint64_t tiles = 0;          // distinct tiles
  std::vector<std::uint8_t> tiled;  // their codes, sorted, a zstd frame
};

// `node` (finished: offsets from its corner, in level order) encoded.
EncodedNode encode_node(const OctreeCube& cube, const std::vector<LodScan>& scans,
                        const BuiltNode& node);

// Writes `node`, replacing the rows of its code. `name` names the file in
// errors.
void put_node(sqlite3* db, const std::string& name, const EncodedNode& node);

// The owners of band of a scan (one a pixel, as LodStore::owners gives
// them) as the store keeps them: one zstd frame.
std::vector<std::uint8_t> compress_owners(std::span<const std::uint32_t> owners);
// Writes the owners of band `band` of the store's scan `scan`, as
// compress_owners compressed them, replacing the band's row.
void put_compressed_owners(sqlite3* db, const std::string& name, std::uint16_t scan, int band,
                           std::span<const std::uint8_t> compressed);

// Writes scan `scan`'s row, replacing it.
void put_scan(sqlite3* db, const std::string& name, const LodScan& scan);

inline std::string node_name(const NodeKey& key) {
  return "node " + std::to_string(key.code()) + " (depth " + std::to_string(key.depth) + ")";
}

}  // namespace scanbench::lod::schema
