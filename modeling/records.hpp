// The checksummed records of the project: a scan's metadata (scans), a
// pose (scan_poses) and a journal entry (commands), with the checksum of
// each as RowChecksum computes it. One definition of each record's fields
// serves the writers, the readers that verify on the way, the migration
// that fills checksums in, and `scanbench check`. Internal to modeling/.
#pragma once

#include <sqlite3.h>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {

struct ScanRecord {
  std::int64_t created_by = 0;
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
  std::string name;
  std::string settings;
  std::string result;
  std::int64_t undoable = 1;
};

std::int64_t checksum(const ScanRecord& record);
std::int64_t checksum(const PoseRecord& record);
std::int64_t checksum(const CommandFields& record);

// The columns of each record, in the order the readers below expect, for
// SELECT lists ("s." / "p." prefixed for the scans-poses join).
inline constexpr const char* kScanRecordColumns =
    "s.created_by, s.name, s.rows, s.columns, s.angle_model, s.azimuth_start_rad, "
    "s.azimuth_step_rad, s.elevation_start_rad, s.elevation_step_rad, s.scanner_name, "
    "s.source_file, s.valid_points, s.has_color, s.has_intensity, s.content_digest, s.checksum";
inline constexpr int kScanRecordColumnCount = 16;
inline constexpr const char* kPoseRecordColumns =
    "p.scan_id, p.command_id, p.T_world_scan, p.scanner_x, p.scanner_y, p.scanner_z, "
    "p.bbox_min_x, p.bbox_min_y, p.bbox_min_z, p.bbox_max_x, p.bbox_max_y, p.bbox_max_z, "
    "p.checksum";
inline constexpr int kPoseRecordColumnCount = 13;

// Reads a record from `row` starting at column `first`, with the checksum
// stored beside it.
std::pair<ScanRecord, std::int64_t> read_scan_record(const sqlite::Statement& row, int first);
std::pair<PoseRecord, std::int64_t> read_pose_record(const sqlite::Statement& row, int first);

// Computes and stores the checksums (and scans' content digests) of every
// row the migration from an older version copied; inside its transaction.
void fill_migrated_checksums(sqlite3* db, const std::string& file);

}  // namespace scanbench::modeling
