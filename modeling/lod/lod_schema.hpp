// What the level-of-detail store's reader and writer share: its SQLite
// identity and schema, and how both name what they find damaged. Internal
// to modeling/lod/.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "core/errors.hpp"
#include "modeling/lod/octree_cube.hpp"
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
  pose BLOB NOT NULL CHECK (length(pose) = 128));
CREATE TABLE lod_nodes (
  code INTEGER PRIMARY KEY CHECK (code >= 1),
  leaf INTEGER NOT NULL CHECK (leaf IN (0, 1)),
  points_below INTEGER NOT NULL,
  points INTEGER NOT NULL CHECK (points >= 0 AND points <= points_below),
  level_ends BLOB NOT NULL CHECK (length(level_ends) = 36),
  bounds BLOB NOT NULL CHECK (length(bounds) = 24),
  max_radius REAL NOT NULL,
  data BLOB NOT NULL);
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

inline sqlite3* connect(const std::filesystem::path& file, int flags) {
  return store::sqlite::open_connection(file.string(), flags, "opening the level-of-detail store");
}

inline std::string node_name(const NodeKey& key) {
  return "node " + std::to_string(key.code()) + " (depth " + std::to_string(key.depth) + ")";
}

}  // namespace scanbench::lod::schema
