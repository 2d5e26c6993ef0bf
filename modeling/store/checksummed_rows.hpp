// The checksummed records of the project: a scan's metadata (scans), a
// pose (scan_poses), a journal entry (commands) and a layer's row
// (scan_layers; its data is checked by its own zstd frame), with the
// checksum of each as RowChecksum computes it. One definition of each record's fields
// serves the writers, the readers that verify on the way, the migration
// that fills checksums in, and `scanbench check`. Internal to modeling/.
#pragma once

#include <sqlite3.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store {

// The columns of one row of each table, as stored; the structs hold no
// meaning beyond that (the Project turns them into summaries and poses).
struct ScanRecord {
  std::int64_t created_by = 0;  // the command that imported it
  std::string name;
  std::int64_t rows = 0;
  std::int64_t columns = 0;
  std::string angle_model;
  std::array<std::optional<double>, 4> angles;  // azimuth start, step, elevation start, step
  std::string scanner_name;
  std::string source_file;
  std::int64_t valid_points = 0;
  std::int64_t has_color = 0;
  std::int64_t has_intensity = 0;
  std::int64_t content_digest = 0;
  std::string layout = "grid";  // or "scattered" (acquisition::PerPixelDirections)
};

struct PoseRecord {
  std::int64_t scan_id = 0;
  std::int64_t command_id = 0;
  std::vector<std::uint8_t> pose;  // 16 little-endian doubles, row-major
  std::array<double, 3> scanner{};
  std::array<std::optional<double>, 6> bbox;  // min x y z, max x y z
};

struct CommandFields {
  std::int64_t id = 0;
  std::optional<std::int64_t> seq;  // none while pending
  std::string name;
  std::string settings;
  std::string result;
  std::string state;
  std::int64_t undoable = 1;
};

// A version of a node of the object tree.
struct NodeRecord {
  std::int64_t node_id = 0;
  std::int64_t command_id = 0;
  std::int64_t live = 1;
  std::string name;
  std::string kind;                    // "group" or "object"
  std::optional<std::int64_t> parent;  // none: a root
  std::int64_t hidden = 0;
  std::int64_t points = 0;
  std::optional<double> mean_footprint_m;
  std::array<std::optional<double>, 6> bbox;  // min x y z, max x y z
  std::string color_edit;                     // JSON; "" for none
};

// A version of a scan's colour correction.
struct ScanColorRecord {
  std::int64_t scan_id = 0;
  std::int64_t command_id = 0;
  std::string correction;  // JSON
};

// What a scan's source file says of it.
struct ScanSourceRecord {
  std::int64_t scan_id = 0;
  std::string details;  // JSON
};

// An image's row without its data (checked by data_crc).
struct ImageRecord {
  std::int64_t created_by = 0;
  std::optional<std::int64_t> scan_id;
  std::string description;  // JSON
  std::string format;
  std::int64_t data_crc = 0;
};

// A layer version's row without its data (whose zstd frame checks itself).
struct LayerFields {
  std::int64_t scan_id = 0;
  std::string name;
  std::int64_t command_id = 0;
  std::string element_type;
  std::int64_t element_count = 0;
  std::string codec;
};

// The CRC-32 of a record's fields (RowChecksum), what its `checksum` column
// holds. Every field counts, NULLs and the bits of -0.0 included.
std::int64_t checksum(const ScanRecord& record);
std::int64_t checksum(const PoseRecord& record);
std::int64_t checksum(const CommandFields& record);
std::int64_t checksum(const LayerFields& record);
std::int64_t checksum(const NodeRecord& record);
std::int64_t checksum(const ScanColorRecord& record);
std::int64_t checksum(const ScanSourceRecord& record);
std::int64_t checksum(const ImageRecord& record);

// What identifies a scan's data whatever its name or pose (the same file
// imported twice has the same): CRC-32 of its grid size, angle model and
// raw range and validity bytes. Independent of how layers are compressed.
std::int64_t content_digest(std::int64_t rows, std::int64_t columns, std::string_view angle_model,
                            std::span<const std::byte> range, std::span<const std::byte> valid);

// The columns of each record, in the order the readers below expect, for
// SELECT lists ("s." / "p." prefixed for the scans-poses join).
// A scan record's columns up to the layout, which schema 9 added.
inline constexpr const char* kScanRecordColumnsBeforeLayout =
    "s.created_by, s.name, s.rows, s.columns, s.angle_model, s.azimuth_start_rad, "
    "s.azimuth_step_rad, s.elevation_start_rad, s.elevation_step_rad, s.scanner_name, "
    "s.source_file, s.valid_points, s.has_color, s.has_intensity, s.content_digest, ";
inline const std::string kScanRecordColumns =
    std::string(kScanRecordColumnsBeforeLayout) + "s.layout, s.checksum";
inline constexpr int kScanRecordColumnCount = 17;
inline constexpr const char* kPoseRecordColumns =
    "p.scan_id, p.command_id, p.T_world_scan, p.scanner_x, p.scanner_y, p.scanner_z, "
    "p.bbox_min_x, p.bbox_min_y, p.bbox_min_z, p.bbox_max_x, p.bbox_max_y, p.bbox_max_z, "
    "p.checksum";
inline constexpr int kPoseRecordColumnCount = 13;
inline constexpr const char* kCommandColumns =
    "id, seq, name, settings, result, state, undoable, created_at, checksum";
inline constexpr const char* kLayerColumns =
    "l.scan_id, l.name, l.command_id, l.element_type, l.element_count, l.codec, l.checksum";

inline constexpr const char* kNodeColumns =
    "n.node_id, n.command_id, n.live, n.name, n.kind, n.parent, n.hidden, n.points, "
    "n.mean_footprint_m, n.bbox_min_x, n.bbox_min_y, n.bbox_min_z, n.bbox_max_x, n.bbox_max_y, "
    "n.bbox_max_z, n.color_edit, n.checksum";

// The parts of an SQL statement put together (plain appends: GCC 12 warns
// falsely on chains of std::string operator+ at -O3).
std::string sql_of(std::initializer_list<std::string_view> parts);

// Reads a record from `row` (a statement selecting kScanRecordColumns or
// kPoseRecordColumns) starting at column `first`, with the checksum stored
// beside it; the caller compares.
std::pair<ScanRecord, std::int64_t> read_scan_record(const sqlite::Statement& row, int first);
std::pair<PoseRecord, std::int64_t> read_pose_record(const sqlite::Statement& row, int first);
// A statement selecting kCommandColumns, from column 0.
std::pair<CommandFields, std::int64_t> read_command_fields(const sqlite::Statement& row);
// A statement selecting kLayerColumns, from column `first`.
std::pair<LayerFields, std::int64_t> read_layer_fields(const sqlite::Statement& row, int first);

// A statement selecting kNodeColumns, from column 0.
std::pair<NodeRecord, std::int64_t> read_node_record(const sqlite::Statement& row);

// Computes and stores the checksums (and scans' content digests) of every
// row the migration from an older version copied; inside its transaction.
void fill_migrated_checksums(sqlite3* db, const std::string& file);

}  // namespace scanbench::store
