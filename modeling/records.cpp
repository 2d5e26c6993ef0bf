#include "modeling/records.hpp"

#include "modeling/row_checksum.hpp"

namespace scanbench::modeling {
namespace {

std::optional<double> optional_double(const sqlite::Statement& row, int column) {
  if (row.is_null(column)) return std::nullopt;
  return row.column_double(column);
}

}  // namespace

std::int64_t checksum(const ScanRecord& r) {
  RowChecksum sum;
  sum.add(r.created_by).add(r.name).add(r.rows).add(r.columns).add(r.angle_model);
  for (const std::optional<double>& angle : r.angles) sum.add(angle);
  sum.add(r.scanner_name).add(r.source_file).add(r.valid_points).add(r.has_color);
  sum.add(r.has_intensity).add(r.content_digest);
  return sum.value();
}

std::int64_t checksum(const PoseRecord& r) {
  RowChecksum sum;
  sum.add(r.scan_id).add(r.command_id).add(std::span<const std::uint8_t>(r.pose));
  for (const double v : r.scanner) sum.add(v);
  for (const std::optional<double>& v : r.bbox) sum.add(v);
  return sum.value();
}

std::int64_t checksum(const CommandFields& r) {
  return RowChecksum().add(r.id).add(r.name).add(r.settings).add(r.result).add(r.undoable).value();
}

std::pair<ScanRecord, std::int64_t> read_scan_record(const sqlite::Statement& row, int c) {
  ScanRecord r;
  r.created_by = row.column_int(c);
  r.name = row.column_text(c + 1);
  r.rows = row.column_int(c + 2);
  r.columns = row.column_int(c + 3);
  r.angle_model = row.column_text(c + 4);
  for (int k = 0; k < 4; ++k)
    r.angles[static_cast<std::size_t>(k)] = optional_double(row, c + 5 + k);
  r.scanner_name = row.column_text(c + 9);
  r.source_file = row.column_text(c + 10);
  r.valid_points = row.column_int(c + 11);
  r.has_color = row.column_int(c + 12);
  r.has_intensity = row.column_int(c + 13);
  r.content_digest = row.column_int(c + 14);
  return {std::move(r), row.column_int(c + 15)};
}

std::pair<PoseRecord, std::int64_t> read_pose_record(const sqlite::Statement& row, int c) {
  PoseRecord r;
  r.scan_id = row.column_int(c);
  r.command_id = row.column_int(c + 1);
  const std::span<const std::uint8_t> pose = row.column_blob(c + 2);
  r.pose.assign(pose.begin(), pose.end());
  for (int k = 0; k < 3; ++k) r.scanner[static_cast<std::size_t>(k)] = row.column_double(c + 3 + k);
  for (int k = 0; k < 6; ++k) r.bbox[static_cast<std::size_t>(k)] = optional_double(row, c + 6 + k);
  return {std::move(r), row.column_int(c + 12)};
}

void fill_migrated_checksums(sqlite3* db, const std::string& file) {
  // Content digests: the CRC of the stored range and valid layers, as
  // content_digest() computes it for new scans.
  std::vector<std::pair<std::int64_t, std::uint32_t>> digests;
  for (sqlite::Statement select(db,
                                "SELECT scan_id, data FROM scan_layers WHERE name IN "
                                "('range_m', 'valid') ORDER BY scan_id, name",
                                file);
       select.step();) {
    if (digests.empty() || digests.back().first != select.column_int(0)) {
      digests.emplace_back(select.column_int(0), 0);
    }
    digests.back().second = crc32_of(std::as_bytes(select.column_blob(1)), digests.back().second);
  }
  for (const auto& [id, digest] : digests) {
    sqlite::Statement update(db, "UPDATE scans SET content_digest = ?2 WHERE id = ?1", file);
    update.bind_int(1, id).bind_int(2, digest).run();
  }
  // Each table read whole first, then updated: no row changes under a
  // statement that is still reading it.
  std::vector<std::pair<std::int64_t, std::int64_t>> sums;  // (key, checksum)
  const std::string scans_sql = std::string("SELECT s.id, ") + kScanRecordColumns + " FROM scans s";
  for (sqlite::Statement scans(db, scans_sql.c_str(), file); scans.step();) {
    sums.emplace_back(scans.column_int(0), checksum(read_scan_record(scans, 1).first));
  }
  for (const auto& [id, sum] : sums) {
    sqlite::Statement update(db, "UPDATE scans SET checksum = ?2 WHERE id = ?1", file);
    update.bind_int(1, id).bind_int(2, sum).run();
  }
  std::vector<PoseRecord> poses;
  const std::string poses_sql = std::string("SELECT ") + kPoseRecordColumns + " FROM scan_poses p";
  for (sqlite::Statement select(db, poses_sql.c_str(), file); select.step();) {
    poses.push_back(read_pose_record(select, 0).first);
  }
  for (const PoseRecord& record : poses) {
    sqlite::Statement update(
        db, "UPDATE scan_poses SET checksum = ?3 WHERE scan_id = ?1 AND command_id = ?2", file);
    update.bind_int(1, record.scan_id).bind_int(2, record.command_id);
    update.bind_int(3, checksum(record)).run();
  }
  sums.clear();
  for (sqlite::Statement commands(db, "SELECT id, name, settings, result, undoable FROM commands",
                                  file);
       commands.step();) {
    const CommandFields record{commands.column_int(0), commands.column_text(1),
                               commands.column_text(2), commands.column_text(3),
                               commands.column_int(4)};
    sums.emplace_back(record.id, checksum(record));
  }
  for (const auto& [id, sum] : sums) {
    sqlite::Statement update(db, "UPDATE commands SET checksum = ?2 WHERE id = ?1", file);
    update.bind_int(1, id).bind_int(2, sum).run();
  }
}

}  // namespace scanbench::modeling
