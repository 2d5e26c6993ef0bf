#include "modeling/store/schema.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <sstream>

#include "core/errors.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store::schema {

namespace {

// Double-valued columns are declared without a type on purpose: a REAL
// column lets SQLite store integral values as integers, which turns -0.0 into
// +0.0, and load_scan promises bit-identical poses and angles. The CHECKs keep
// the columns honest instead (SQLite binds NaN as NULL, so NaN is refused).
constexpr const char* kCreateVersion1 = R"sql(
CREATE TABLE meta (
  key TEXT PRIMARY KEY NOT NULL,
  value TEXT NOT NULL
);
CREATE TABLE scans (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL,
  rows INTEGER NOT NULL CHECK (rows >= 0),
  columns INTEGER NOT NULL CHECK (columns >= 0),
  angle_model TEXT NOT NULL CHECK (angle_model IN ('spherical', 'per_pixel')),
  azimuth_start_rad CHECK (typeof(azimuth_start_rad) IN ('real', 'null')),
  azimuth_step_rad CHECK (typeof(azimuth_step_rad) IN ('real', 'null')),
  elevation_start_rad CHECK (typeof(elevation_start_rad) IN ('real', 'null')),
  elevation_step_rad CHECK (typeof(elevation_step_rad) IN ('real', 'null')),
  T_world_scan BLOB NOT NULL CHECK (length(T_world_scan) = 128),
  scanner_name TEXT NOT NULL,
  source_file TEXT NOT NULL,
  scanner_x NOT NULL CHECK (typeof(scanner_x) = 'real'),
  scanner_y NOT NULL CHECK (typeof(scanner_y) = 'real'),
  scanner_z NOT NULL CHECK (typeof(scanner_z) = 'real'),
  valid_points INTEGER NOT NULL CHECK (valid_points >= 0),
  has_color INTEGER NOT NULL CHECK (has_color IN (0, 1)),
  has_intensity INTEGER NOT NULL CHECK (has_intensity IN (0, 1)),
  bbox_min_x CHECK (typeof(bbox_min_x) IN ('real', 'null')),
  bbox_min_y CHECK (typeof(bbox_min_y) IN ('real', 'null')),
  bbox_min_z CHECK (typeof(bbox_min_z) IN ('real', 'null')),
  bbox_max_x CHECK (typeof(bbox_max_x) IN ('real', 'null')),
  bbox_max_y CHECK (typeof(bbox_max_y) IN ('real', 'null')),
  bbox_max_z CHECK (typeof(bbox_max_z) IN ('real', 'null')),
  created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
  CHECK ((angle_model = 'spherical') =
         (azimuth_start_rad IS NOT NULL AND azimuth_step_rad IS NOT NULL AND
          elevation_start_rad IS NOT NULL AND elevation_step_rad IS NOT NULL)),
  CHECK ((bbox_min_x IS NULL) = (bbox_max_z IS NULL))
);
CREATE TABLE scan_channels (
  scan_id INTEGER NOT NULL REFERENCES scans (id) ON DELETE CASCADE,
  channel TEXT NOT NULL
    CHECK (channel IN ('range_m', 'valid', 'intensity', 'rgb', 'directions')),
  element_count INTEGER NOT NULL CHECK (element_count >= 0),
  codec TEXT NOT NULL CHECK (codec = 'zstd'),
  data BLOB NOT NULL,
  PRIMARY KEY (scan_id, channel)
);
)sql";

constexpr const char* kRecordCreation = R"sql(
INSERT INTO meta (key, value) VALUES
  ('created_by', 'scanbench'),
  ('created_at', strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
  ('created_schema_version', ?1)
)sql";

// Tables every version has (checked before migrating) and those of the
// current version (checked after).
constexpr std::array<const char*, 2> kEveryVersionTables = {"meta", "scans"};
constexpr std::array<const char*, 9> kCurrentTables = {
    "meta",         "scans",       "commands",     "scan_poses", "scan_layers",
    "object_nodes", "scan_colors", "scan_sources", "scan_images"};

[[noreturn]] void refuse(const std::string& file, const std::string& problem) {
  throw core::InputError(file, {}, problem);
}

std::uint32_t big_endian_u32(const char* bytes) {
  std::uint32_t value = 0;
  for (int i = 0; i < 4; ++i) value = (value << 8) | static_cast<unsigned char>(bytes[i]);
  return value;
}

// The same rules apply to the raw header and to what SQLite reports.
void check_identity(std::uint32_t application_id, std::int64_t version, const std::string& file) {
  if (application_id != kProjectApplicationId) {
    std::ostringstream id;
    id << std::hex << "0x" << application_id;
    refuse(file,
           "not a scanbench project (SQLite database of another application, "
           "application_id " +
               id.str() + ")");
  }
  if (version > kProjectSchemaVersion) {
    refuse(file, "project schema version " + std::to_string(version) +
                     " is newer than this scanbench (" + std::to_string(kProjectSchemaVersion) +
                     "); upgrade scanbench");
  }
  if (version < 1) refuse(file, "project has no schema version (damaged or unfinished project)");
}

std::int64_t pragma_value(sqlite3* db, const char* pragma, const std::string& file) {
  sqlite::Statement statement(db, pragma, file);
  if (!statement.step()) refuse(file, std::string("no result from ") + pragma);
  return statement.column_int(0);
}

template <std::size_t N>
void check_tables(sqlite3* db, const std::string& file, const std::array<const char*, N>& tables) {
  for (const char* table : tables) {
    sqlite::Statement statement(
        db, "SELECT 1 FROM sqlite_schema WHERE type = 'table' AND name = ?1", file);
    statement.bind_text(1, table);
    if (!statement.step()) {
      refuse(file, std::string("project is damaged: table \"") + table + "\" is missing");
    }
  }
}

// Version 2: per-point geometry (footprint, normal, confidence, flags) of
// each scan, from `scanbench geometry`, with the settings that produced it.
constexpr const char* kMigrate1To2 = R"sql(
CREATE TABLE scan_geometry (
  scan_id INTEGER PRIMARY KEY REFERENCES scans (id) ON DELETE CASCADE,
  settings TEXT NOT NULL,
  normals INTEGER NOT NULL CHECK (normals >= 0),
  mixed_pixels INTEGER NOT NULL CHECK (mixed_pixels >= 0),
  edge_pixels INTEGER NOT NULL CHECK (edge_pixels >= 0),
  footprint_m BLOB NOT NULL,
  normal BLOB NOT NULL,
  confidence BLOB NOT NULL,
  flags BLOB NOT NULL,
  computed_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
)sql";

// Version 3: the reports of `scanbench register` (JSON, one row per run) and
// the keep masks of `scanbench merge` (one zstd-compressed byte per pixel).
constexpr const char* kMigrate2To3 = R"sql(
CREATE TABLE registration_runs (
  id INTEGER PRIMARY KEY,
  settings TEXT NOT NULL,
  report TEXT NOT NULL,
  created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
CREATE TABLE merge_masks (
  scan_id INTEGER PRIMARY KEY REFERENCES scans (id) ON DELETE CASCADE,
  settings TEXT NOT NULL,
  kept_points INTEGER NOT NULL CHECK (kept_points >= 0),
  keep BLOB NOT NULL,
  computed_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
)sql";

// Version 4: the command journal, and nothing overwritten any more. The
// scans table keeps what an import fixes for good; poses move to
// scan_poses and every per-pixel array (channels, geometry, keep masks) to
// scan_layers, one version per command that wrote it (project.hpp).
//
// What an older project holds becomes journal entries that cannot be
// undone, in the order it was made: "migrate" (id 1: the scans and their
// current poses, at the project's creation time), "geometry" (id 2: the
// geometry layers, with the settings and counts stored beside them), one
// "register" per registration run (ids from 4, with its report), and
// "merge" (id 3: the keep masks, with their settings). Each exists only when
// there is such data. ?1: the schema version the file had.
constexpr const char* kMigrate3To4 = R"sql(
CREATE TABLE commands (
  id INTEGER PRIMARY KEY AUTOINCREMENT,  -- never reused: a journal id names one command for good
  seq INTEGER UNIQUE,                    -- journal order, given when the command is done
  name TEXT NOT NULL,
  settings TEXT NOT NULL,
  result TEXT NOT NULL DEFAULT '{}',
  state TEXT NOT NULL CHECK (state IN ('pending', 'done', 'undone')),
  undoable INTEGER NOT NULL CHECK (undoable IN (0, 1)),
  owner_machine TEXT,  -- pending: the process writing it (core::ProcessIdentity)
  owner_pid INTEGER,
  owner_start INTEGER,
  checksum INTEGER NOT NULL DEFAULT 0,   -- of id, seq, name, settings, result, state, undoable
  created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
  CHECK ((state = 'pending') = (seq IS NULL))
);
INSERT INTO commands (id, seq, name, settings, result, state, undoable, created_at)
  SELECT 1, 1, 'migrate', '{"from_schema_version":' || ?1 || '}', '{}', 'done', 0,
         coalesce((SELECT value FROM meta WHERE key = 'created_at'),
                  strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
  WHERE EXISTS (SELECT 1 FROM scans);
INSERT INTO commands (id, seq, name, settings, result, state, undoable, created_at)
  SELECT 2, 2, 'geometry', (SELECT settings FROM scan_geometry ORDER BY scan_id LIMIT 1),
         '{"scans":[' || group_concat('{"id":' || scan_id || ',"normals":' || normals ||
                                      ',"mixed_pixels":' || mixed_pixels || ',"edge_pixels":' ||
                                      edge_pixels || '}') || ']}',
         'done', 0, max(computed_at)
  FROM scan_geometry HAVING count(*) > 0;
INSERT INTO commands (id, seq, name, settings, result, state, undoable, created_at)
  SELECT 3 + row_number() OVER (ORDER BY id), 2 + row_number() OVER (ORDER BY id), 'register',
         settings, report, 'done', 0, created_at
  FROM registration_runs;
INSERT INTO commands (id, seq, name, settings, result, state, undoable, created_at)
  SELECT 3, 3 + (SELECT count(*) FROM registration_runs),
         'merge', (SELECT settings FROM merge_masks ORDER BY scan_id LIMIT 1),
         '{"kept":' || sum(kept_points) || '}', 'done', 0, max(computed_at)
  FROM merge_masks HAVING count(*) > 0;

ALTER TABLE scans RENAME TO scans_v3;
CREATE TABLE scans (
  id INTEGER PRIMARY KEY AUTOINCREMENT,  -- never reused: a scan id names one scan for good
  created_by INTEGER NOT NULL REFERENCES commands (id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  rows INTEGER NOT NULL CHECK (rows >= 0),
  columns INTEGER NOT NULL CHECK (columns >= 0),
  angle_model TEXT NOT NULL CHECK (angle_model IN ('spherical', 'per_pixel')),
  azimuth_start_rad CHECK (typeof(azimuth_start_rad) IN ('real', 'null')),
  azimuth_step_rad CHECK (typeof(azimuth_step_rad) IN ('real', 'null')),
  elevation_start_rad CHECK (typeof(elevation_start_rad) IN ('real', 'null')),
  elevation_step_rad CHECK (typeof(elevation_step_rad) IN ('real', 'null')),
  scanner_name TEXT NOT NULL,
  source_file TEXT NOT NULL,
  valid_points INTEGER NOT NULL CHECK (valid_points >= 0),
  has_color INTEGER NOT NULL CHECK (has_color IN (0, 1)),
  has_intensity INTEGER NOT NULL CHECK (has_intensity IN (0, 1)),
  content_digest INTEGER NOT NULL DEFAULT 0,  -- CRC of the range and valid layers: finds twins
  checksum INTEGER NOT NULL DEFAULT 0,        -- of every column above but the id
  created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
  CHECK ((angle_model = 'spherical') =
         (azimuth_start_rad IS NOT NULL AND azimuth_step_rad IS NOT NULL AND
          elevation_start_rad IS NOT NULL AND elevation_step_rad IS NOT NULL))
);
CREATE INDEX scans_by_command ON scans (created_by);
CREATE TABLE scan_poses (
  scan_id INTEGER NOT NULL REFERENCES scans (id) ON DELETE CASCADE,
  command_id INTEGER NOT NULL REFERENCES commands (id) ON DELETE CASCADE,
  T_world_scan BLOB NOT NULL CHECK (length(T_world_scan) = 128),
  scanner_x NOT NULL CHECK (typeof(scanner_x) = 'real'),
  scanner_y NOT NULL CHECK (typeof(scanner_y) = 'real'),
  scanner_z NOT NULL CHECK (typeof(scanner_z) = 'real'),
  bbox_min_x CHECK (typeof(bbox_min_x) IN ('real', 'null')),
  bbox_min_y CHECK (typeof(bbox_min_y) IN ('real', 'null')),
  bbox_min_z CHECK (typeof(bbox_min_z) IN ('real', 'null')),
  bbox_max_x CHECK (typeof(bbox_max_x) IN ('real', 'null')),
  bbox_max_y CHECK (typeof(bbox_max_y) IN ('real', 'null')),
  bbox_max_z CHECK (typeof(bbox_max_z) IN ('real', 'null')),
  checksum INTEGER NOT NULL DEFAULT 0,  -- of every column above
  CHECK ((bbox_min_x IS NULL) = (bbox_max_z IS NULL)),
  PRIMARY KEY (scan_id, command_id)
);
CREATE INDEX scan_poses_by_command ON scan_poses (command_id);
CREATE TABLE scan_layers (
  scan_id INTEGER NOT NULL REFERENCES scans (id) ON DELETE CASCADE,
  name TEXT NOT NULL CHECK (length(name) BETWEEN 1 AND 64),
  command_id INTEGER NOT NULL REFERENCES commands (id) ON DELETE CASCADE,
  element_type TEXT NOT NULL CHECK (element_type IN ('u8', 'u8x3', 'u32', 'f32', 'f32x3')),
  element_count INTEGER NOT NULL CHECK (element_count >= 0),
  codec TEXT NOT NULL CHECK (codec IN ('zstd', 'removed')),
  data BLOB CHECK ((codec = 'removed') = (data IS NULL)),  -- zstd frames check their own content
  checksum INTEGER NOT NULL DEFAULT 0,  -- of every column above but data
  PRIMARY KEY (scan_id, name, command_id)
);
CREATE INDEX scan_layers_by_command ON scan_layers (command_id);

INSERT INTO scans (id, created_by, name, rows, columns, angle_model, azimuth_start_rad,
                   azimuth_step_rad, elevation_start_rad, elevation_step_rad, scanner_name,
                   source_file, valid_points, has_color, has_intensity, created_at)
  SELECT id, 1, name, rows, columns, angle_model, azimuth_start_rad, azimuth_step_rad,
         elevation_start_rad, elevation_step_rad, scanner_name, source_file, valid_points,
         has_color, has_intensity, created_at
  FROM scans_v3;
INSERT INTO scan_poses (scan_id, command_id, T_world_scan, scanner_x, scanner_y, scanner_z,
                        bbox_min_x, bbox_min_y, bbox_min_z, bbox_max_x, bbox_max_y, bbox_max_z)
  SELECT id, 1, T_world_scan, scanner_x, scanner_y, scanner_z, bbox_min_x, bbox_min_y,
         bbox_min_z, bbox_max_x, bbox_max_y, bbox_max_z
  FROM scans_v3;
INSERT INTO scan_layers (scan_id, name, command_id, element_type, element_count, codec, data)
  SELECT scan_id, channel, 1,
         CASE channel WHEN 'valid' THEN 'u8' WHEN 'rgb' THEN 'u8x3'
                      WHEN 'directions' THEN 'f32x3' ELSE 'f32' END,
         CASE channel WHEN 'rgb' THEN element_count / 3 ELSE element_count END, codec, data
  FROM scan_channels;
INSERT INTO scan_layers (scan_id, name, command_id, element_type, element_count, codec, data)
  SELECT g.scan_id, 'footprint_m', 2, 'f32', s.rows * s.columns, 'zstd', g.footprint_m
  FROM scan_geometry g JOIN scans s ON s.id = g.scan_id
  UNION ALL
  SELECT g.scan_id, 'normal', 2, 'f32x3', s.rows * s.columns, 'zstd', g.normal
  FROM scan_geometry g JOIN scans s ON s.id = g.scan_id
  UNION ALL
  SELECT g.scan_id, 'confidence', 2, 'f32', s.rows * s.columns, 'zstd', g.confidence
  FROM scan_geometry g JOIN scans s ON s.id = g.scan_id
  UNION ALL
  SELECT g.scan_id, 'geometry_flags', 2, 'u8', s.rows * s.columns, 'zstd', g.flags
  FROM scan_geometry g JOIN scans s ON s.id = g.scan_id
  UNION ALL
  SELECT m.scan_id, 'keep', 3, 'u8', s.rows * s.columns, 'zstd', m.keep
  FROM merge_masks m JOIN scans s ON s.id = m.scan_id;

DROP TABLE scan_channels;
DROP TABLE scan_geometry;
DROP TABLE merge_masks;
DROP TABLE registration_runs;
DROP TABLE scans_v3;
INSERT OR REPLACE INTO meta (key, value) VALUES ('revision', '0');
)sql";

// Version 5: the object tree (site → building → wall …). One row per
// version of a node, as for poses: what the project holds is each node's
// row of the newest done command, `live` 0 when that command deleted it.
// Which pixels an object owns, and the selection being grown, are layers
// ("membership", "selection"), so they need no table.
constexpr const char* kMigrate4To5 = R"sql(
CREATE TABLE object_nodes (
  node_id INTEGER NOT NULL CHECK (node_id > 0),
  command_id INTEGER NOT NULL REFERENCES commands (id) ON DELETE CASCADE,
  live INTEGER NOT NULL CHECK (live IN (0, 1)),
  name TEXT NOT NULL,
  kind TEXT NOT NULL CHECK (kind IN ('group', 'object')),
  parent INTEGER CHECK (parent IS NULL OR parent > 0),  -- a node_id; NULL: a root
  hidden INTEGER NOT NULL CHECK (hidden IN (0, 1)),
  points INTEGER NOT NULL CHECK (points >= 0),
  mean_footprint_m CHECK (typeof(mean_footprint_m) IN ('real', 'null')),
  bbox_min_x CHECK (typeof(bbox_min_x) IN ('real', 'null')),
  bbox_min_y CHECK (typeof(bbox_min_y) IN ('real', 'null')),
  bbox_min_z CHECK (typeof(bbox_min_z) IN ('real', 'null')),
  bbox_max_x CHECK (typeof(bbox_max_x) IN ('real', 'null')),
  bbox_max_y CHECK (typeof(bbox_max_y) IN ('real', 'null')),
  bbox_max_z CHECK (typeof(bbox_max_z) IN ('real', 'null')),
  checksum INTEGER NOT NULL DEFAULT 0,  -- of every column above
  CHECK ((bbox_min_x IS NULL) = (bbox_max_z IS NULL)),
  PRIMARY KEY (node_id, command_id)
);
CREATE INDEX object_nodes_by_command ON object_nodes (command_id);
)sql";

// Version 6: each node's own colour edit (JSON, "" for none; old rows keep
// their checksums, which an empty edit does not change), and the versioned
// colour corrections of scans (`harmonize`).
constexpr const char* kMigrate5To6 = R"sql(
ALTER TABLE object_nodes ADD COLUMN color_edit TEXT NOT NULL DEFAULT '';
CREATE TABLE scan_colors (
  scan_id INTEGER NOT NULL REFERENCES scans (id) ON DELETE CASCADE,
  command_id INTEGER NOT NULL REFERENCES commands (id) ON DELETE CASCADE,
  correction TEXT NOT NULL,
  checksum INTEGER NOT NULL,
  PRIMARY KEY (scan_id, command_id)
);
CREATE INDEX scan_colors_by_command ON scan_colors (command_id);
)sql";

// Version 7: what a scan's source file says of it beside the grid (its
// E57 guid, the records it held and those the grid could not place), and
// the images that came with the scans (E57 images2D), each tied to its
// scan or to none. Both are written by the import that made the scan and
// go with it.
constexpr const char* kMigrate6To7 = R"sql(
CREATE TABLE scan_sources (
  scan_id INTEGER PRIMARY KEY REFERENCES scans (id) ON DELETE CASCADE,
  details TEXT NOT NULL,  -- JSON (acquisition::ScanSource)
  checksum INTEGER NOT NULL
);
CREATE TABLE scan_images (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  created_by INTEGER NOT NULL REFERENCES commands (id) ON DELETE CASCADE,
  scan_id INTEGER REFERENCES scans (id) ON DELETE CASCADE,  -- NULL: tied to no scan
  description TEXT NOT NULL,  -- JSON: name, guid, projection, sizes, pose
  format TEXT NOT NULL CHECK (format IN ('jpeg', 'png')),
  data BLOB NOT NULL,
  data_crc INTEGER NOT NULL,  -- CRC-32 of data
  checksum INTEGER NOT NULL   -- of every column above but the id and data
);
CREATE INDEX scan_images_by_command ON scan_images (created_by);
)sql";

// Version 8: the journal's commands that are not done found without
// reading the whole journal: each new command ends the redo branch and
// clears what killed writers left, and redo finds the oldest undone one.
constexpr const char* kMigrate7To8 = R"sql(
CREATE INDEX commands_undone ON commands (seq) WHERE state = 'undone';
CREATE INDEX commands_pending ON commands (id) WHERE state = 'pending';
)sql";

// Version 9: a scan's layout: a grid, or an unstructured cloud kept as a
// list of points (acquisition::PerPixelDirections::scattered). Grid rows
// keep their checksums: the default layout adds nothing to them.
constexpr const char* kMigrate8To9 = R"sql(
ALTER TABLE scans ADD COLUMN layout TEXT NOT NULL DEFAULT 'grid'
  CHECK (layout IN ('grid', 'scattered'));
)sql";

// Version 10: a layer's zstd frame may sit in a column of its own, last in
// the row, with `data` left empty: SQLite writes a blob that ends its row
// in place (sqlite3_blob_write into a zeroblob), where a blob followed by
// another column is first built whole in memory, twice its size. A stage
// that writes a layer by rows (layer_rows.hpp) stores it there. The rows'
// checksums leave both columns out, as before.
constexpr const char* kMigrate9To10 = R"sql(
ALTER TABLE scan_layers ADD COLUMN frame BLOB
  CHECK (frame IS NULL OR (codec = 'zstd' AND length(data) = 0));
)sql";

// Upgrades the schema from `version` to version + 1 inside the caller's
// transaction; `original_version` is the version the file had when opened.
void migrate_step(sqlite3* db, int version, int original_version, const std::string& file) {
  switch (version) {
    case 1:
      sqlite::execute(db, kMigrate1To2, file);
      return;
    case 2:
      sqlite::execute(db, kMigrate2To3, file);
      return;
    case 3:
      sqlite::execute_with_int(db, kMigrate3To4, original_version, file);
      fill_migrated_checksums(db, file);
      return;
    case 4:
      sqlite::execute(db, kMigrate4To5, file);
      return;
    case 5:
      sqlite::execute(db, kMigrate5To6, file);
      return;
    case 6:
      sqlite::execute(db, kMigrate6To7, file);
      return;
    case 7:
      sqlite::execute(db, kMigrate7To8, file);
      return;
    case 8:
      sqlite::execute(db, kMigrate8To9, file);
      return;
    case 9:
      sqlite::execute(db, kMigrate9To10, file);
      return;
    default:
      assert(false && "no migration step from this schema version");
  }
}

// Runs steps(version), with the schema version read under the write lock,
// inside a transaction that ends with the project identity at the current
// version, or rolls everything back. Nothing runs when another process
// brought the file to the current version first.
template <typename Steps>
void in_versioned_transaction(sqlite3* db, const std::string& file, Steps steps) {
  const std::string identity = "PRAGMA application_id = " + std::to_string(kProjectApplicationId) +
                               "; PRAGMA user_version = " + std::to_string(kProjectSchemaVersion);
  sqlite::execute(db, "BEGIN IMMEDIATE", file);
  try {
    const int version = read_schema_version(db, file);
    if (version == kProjectSchemaVersion) {
      sqlite::execute(db, "COMMIT", file);
      return;
    }
    steps(version);
    sqlite::execute(db, identity.c_str(), file);
    sqlite::execute(db, "COMMIT", file);
  } catch (...) {
    sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

void migrate_from(sqlite3* db, int from_version, const std::string& file) {
  for (int version = from_version; version < kProjectSchemaVersion; ++version) {
    migrate_step(db, version, from_version, file);
  }
}

void enable_wal(sqlite3* db, const std::string& file) {
  sqlite::Statement statement(db, "PRAGMA journal_mode = WAL", file);
  if (!statement.step() || statement.column_text(0) != "wal") {
    throw core::RuntimeFailure(
        file, {}, "cannot use write-ahead logging for this file (network file system?)");
  }
}

}  // namespace

void check_file_kind(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  if (!std::filesystem::exists(status)) refuse(name, "project file does not exist");
  if (std::filesystem::is_directory(status)) refuse(name, "is a directory, not a project file");
  if (!std::filesystem::is_regular_file(status)) refuse(name, "is not a regular file");
}

void check_file_header(sqlite3* db, const std::filesystem::path& file) {
  const std::string name = file.string();
  sqlite3_file* handle = nullptr;
  if (sqlite3_file_control(db, "main", SQLITE_FCNTL_FILE_POINTER, &handle) != SQLITE_OK ||
      handle == nullptr || handle->pMethods == nullptr) {
    throw core::RuntimeFailure(name, {}, "cannot read the project file");
  }
  std::error_code error;
  if (std::filesystem::file_size(file, error) == 0 && !error)
    refuse(name, "file is empty, not a scanbench project");
  std::array<char, 100> header{};
  // A short read fills the rest with zeros: no magic, refused below.
  const int read = handle->pMethods->xRead(handle, header.data(), header.size(), 0);
  if (read != SQLITE_OK && read != SQLITE_IOERR_SHORT_READ)
    throw core::RuntimeFailure(name, {}, "cannot read the project file");
  constexpr char kMagic[16] = "SQLite format 3";  // with its terminating NUL: 16 bytes
  if (read == SQLITE_IOERR_SHORT_READ || !std::equal(kMagic, kMagic + 16, header.begin())) {
    refuse(name, "not a scanbench project (not an SQLite database)");
  }
  // SQLite's file format versions (bytes 18 and 19) are 1 or 2; with a
  // higher write version SQLite opens the file read-only, with a higher read
  // version not at all: a damaged header, not a file to open.
  const auto write_version = static_cast<unsigned char>(header[18]);
  const auto read_version = static_cast<unsigned char>(header[19]);
  if (write_version < 1 || write_version > 2 || read_version < 1 || read_version > 2) {
    refuse(name, "project file is damaged: its header gives SQLite file format versions " +
                     std::to_string(write_version) + " and " + std::to_string(read_version) +
                     " (1 or 2 expected)");
  }
  // SQLite file format: user_version at byte 60, application_id at byte 68,
  // both big-endian.
  check_identity(big_endian_u32(header.data() + 68),
                 static_cast<std::int32_t>(big_endian_u32(header.data() + 60)), name);
}

void configure_connection(sqlite3* db, const std::string& file) {
  const int code = sqlite3_busy_timeout(db, kBusyTimeoutMs);
  if (code != SQLITE_OK) sqlite::throw_error(db, code, file, "setting the busy timeout");
  // FULL rather than NORMAL: in WAL mode NORMAL can lose the last commits on
  // power loss, and a user's edit must stay saved once reported as saved.
  sqlite::execute(db, "PRAGMA foreign_keys = ON; PRAGMA synchronous = FULL", file);
}

// New projects take the same path as old ones: the version 1 script, then
// every migration step, so each migration runs in every test that creates a
// project.
void create_schema(sqlite3* db, const std::string& file) {
  in_versioned_transaction(db, file, [&](int) {
    sqlite::execute(db, kCreateVersion1, file);
    migrate_from(db, 1, file);
    sqlite::Statement record(db, kRecordCreation, file);
    record.bind_text(1, std::to_string(kProjectSchemaVersion)).run();
  });
  enable_wal(db, file);
}

void check_and_migrate(sqlite3* db, const std::string& file) {
  const auto application_id =
      static_cast<std::uint32_t>(pragma_value(db, "PRAGMA application_id", file));
  const int version = read_schema_version(db, file);
  check_identity(application_id, version, file);
  check_tables(db, file, kEveryVersionTables);
  if (version < kProjectSchemaVersion) {
    in_versioned_transaction(db, file, [&](int current) { migrate_from(db, current, file); });
  }
  // After the migration: a refused migration leaves the file in its own mode.
  enable_wal(db, file);
  check_tables(db, file, kCurrentTables);
}

void check_readable(sqlite3* db, const std::string& file) {
  const auto application_id =
      static_cast<std::uint32_t>(pragma_value(db, "PRAGMA application_id", file));
  const int version = read_schema_version(db, file);
  check_identity(application_id, version, file);
  if (version < kProjectSchemaVersion) {
    throw core::RuntimeFailure(
        file, {},
        "project of schema version " + std::to_string(version) +
            ", read here without changes: any other command run where it can be written "
            "(scanbench info, for one) upgrades it to version " +
            std::to_string(kProjectSchemaVersion) + " first");
  }
  check_tables(db, file, kCurrentTables);
}

int read_schema_version(sqlite3* db, const std::string& file) {
  return static_cast<int>(pragma_value(db, "PRAGMA user_version", file));
}

}  // namespace scanbench::store::schema
