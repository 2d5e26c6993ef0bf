#include "modeling/store/checksummed_rows.hpp"

#include "modeling/store/row_checksum.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::store {
namespace {

std::optional<double> optional_double(const sqlite::Statement& row, int column) {
  if (row.is_null(column)) return std::nullopt;
  return row.column_double(column);
}

}  // namespace

std::string sql_of(std::initializer_list<std::string_view> parts) {
  std::string sql;
  for (const std::string_view part : parts) sql += part;
  return sql;
}

std::int64_t checksum(const ScanRecord& r) {
  RowChecksum sum;
  sum.add(r.created_by).add(r.name).add(r.rows).add(r.columns).add(r.angle_model);
  for (const std::optional<double>& angle : r.angles) sum.add(angle);
  sum.add(r.scanner_name).add(r.source_file).add(r.valid_points).add(r.has_color);
  sum.add(r.has_intensity).add(r.content_digest);
  // Rows of schema 8 are grids: the default layout adds nothing, so their
  // checksums still hold.
  if (r.layout != "grid") sum.add(r.layout);
  return sum.value();
}

std::int64_t checksum(const PoseRecord& r) {
  RowChecksum sum;
  sum.add(r.scan_id).add(r.command_id).add(std::span<const std::uint8_t>(r.pose));
  for (const double v : r.scanner) sum.add(v);
  for (const std::optional<double>& v : r.bbox) sum.add(v);
  return sum.value();
}

std::int64_t checksum(const NodeRecord& r) {
  RowChecksum sum;
  sum.add(r.node_id).add(r.command_id).add(r.live).add(r.name).add(r.kind);
  sum.add(r.parent ? std::optional<double>(static_cast<double>(*r.parent)) : std::nullopt);
  sum.add(r.hidden).add(r.points).add(r.mean_footprint_m);
  for (const std::optional<double>& v : r.bbox) sum.add(v);
  // Rows of schema 5 have no edit: an empty one adds nothing, so their
  // checksums still hold.
  if (!r.color_edit.empty()) sum.add(r.color_edit);
  return sum.value();
}

std::int64_t checksum(const ScanColorRecord& r) {
  RowChecksum sum;
  sum.add(r.scan_id).add(r.command_id).add(r.correction);
  return sum.value();
}

std::int64_t checksum(const ScanSourceRecord& r) {
  RowChecksum sum;
  sum.add(r.scan_id).add(r.details);
  return sum.value();
}

std::int64_t checksum(const ImageRecord& r) {
  RowChecksum sum;
  sum.add(r.created_by);
  sum.add(r.scan_id ? std::optional<double>(static_cast<double>(*r.scan_id)) : std::nullopt);
  sum.add(r.description).add(r.format).add(r.data_crc);
  return sum.value();
}

std::int64_t content_digest(std::int64_t rows, std::int64_t columns, std::string_view angle_model,
                            std::span<const std::byte> range, std::span<const std::byte> valid) {
  RowChecksum sum;
  sum.add(rows).add(columns).add(angle_model);
  return crc32_of(valid, crc32_of(range, static_cast<std::uint32_t>(sum.value())));
}

std::int64_t checksum(const CommandFields& r) {
  RowChecksum sum;
  sum.add(r.id);
  sum.add(r.seq ? std::optional<double>(static_cast<double>(*r.seq)) : std::nullopt);
  sum.add(r.name).add(r.settings).add(r.result).add(r.state).add(r.undoable);
  return sum.value();
}

std::int64_t checksum(const LayerFields& r) {
  return RowChecksum()
      .add(r.scan_id)
      .add(r.name)
      .add(r.command_id)
      .add(r.element_type)
      .add(r.element_count)
      .add(r.codec)
      .value();
}

std::pair<CommandFields, std::int64_t> read_command_fields(const sqlite::Statement& row) {
  CommandFields r;
  r.id = row.column_int(0);
  if (!row.is_null(1)) r.seq = row.column_int(1);
  r.name = row.column_text(2);
  r.settings = row.column_text(3);
  r.result = row.column_text(4);
  r.state = row.column_text(5);
  r.undoable = row.column_int(6);
  return {std::move(r), row.column_int(8)};
}

std::pair<LayerFields, std::int64_t> read_layer_fields(const sqlite::Statement& row, int c) {
  LayerFields r;
  r.scan_id = row.column_int(c);
  r.name = row.column_text(c + 1);
  r.command_id = row.column_int(c + 2);
  r.element_type = row.column_text(c + 3);
  r.element_count = row.column_int(c + 4);
  r.codec = row.column_text(c + 5);
  return {std::move(r), row.column_int(c + 6)};
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
  r.layout = row.column_text(c + 15);
  return {std::move(r), row.column_int(c + 16)};
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

std::pair<NodeRecord, std::int64_t> read_node_record(const sqlite::Statement& row) {
  NodeRecord r;
  r.node_id = row.column_int(0);
  r.command_id = row.column_int(1);
  r.live = row.column_int(2);
  r.name = row.column_text(3);
  r.kind = row.column_text(4);
  if (!row.is_null(5)) r.parent = row.column_int(5);
  r.hidden = row.column_int(6);
  r.points = row.column_int(7);
  r.mean_footprint_m = optional_double(row, 8);
  for (int k = 0; k < 6; ++k) r.bbox[static_cast<std::size_t>(k)] = optional_double(row, 9 + k);
  r.color_edit = row.column_text(15);
  return {std::move(r), row.column_int(16)};
}

namespace {

// Content digests, from the decoded range and validity (what
// content_digest() takes for new scans).
void fill_content_digests(sqlite3* db, const std::string& file) {
  std::vector<std::pair<std::int64_t, std::int64_t>> digests;
  for (sqlite::Statement select(db, R"sql(
SELECT s.id, s.rows, s.columns, s.angle_model, r.data, v.data
FROM scans s JOIN scan_layers r ON r.scan_id = s.id AND r.name = 'range_m'
             JOIN scan_layers v ON v.scan_id = s.id AND v.name = 'valid')sql",
                                file);
       select.step();) {
    const auto n = static_cast<std::size_t>(select.column_int(1) * select.column_int(2));
    const BlobContext context{file, "scan " + std::to_string(select.column_int(0))};
    const std::vector<std::byte> range = decompress(select.column_blob(4), 4 * n, context);
    const std::vector<std::byte> valid = decompress(select.column_blob(5), n, context);
    digests.emplace_back(select.column_int(0),
                         content_digest(select.column_int(1), select.column_int(2),
                                        select.column_text(3), range, valid));
  }
  for (const auto& [id, digest] : digests) {
    sqlite::Statement update(db, "UPDATE scans SET content_digest = ?2 WHERE id = ?1", file);
    update.bind_int(1, id).bind_int(2, digest).run();
  }
}

// Each table is read whole first, then updated: no row changes under a
// statement that is still reading it.
void fill_scan_and_pose_checksums(sqlite3* db, const std::string& file) {
  std::vector<std::pair<std::int64_t, std::int64_t>> sums;  // (key, checksum)
  // Schema 4 has no layout column: every scan is a grid.
  const std::string scans_sql =
      sql_of({"SELECT s.id, ", kScanRecordColumnsBeforeLayout, "'grid', s.checksum FROM scans s"});
  for (sqlite::Statement scans(db, scans_sql.c_str(), file); scans.step();) {
    sums.emplace_back(scans.column_int(0), checksum(read_scan_record(scans, 1).first));
  }
  for (const auto& [id, sum] : sums) {
    sqlite::Statement update(db, "UPDATE scans SET checksum = ?2 WHERE id = ?1", file);
    update.bind_int(1, id).bind_int(2, sum).run();
  }
  std::vector<PoseRecord> poses;
  const std::string poses_sql = sql_of({"SELECT ", kPoseRecordColumns, " FROM scan_poses p"});
  for (sqlite::Statement select(db, poses_sql.c_str(), file); select.step();) {
    poses.push_back(read_pose_record(select, 0).first);
  }
  for (const PoseRecord& record : poses) {
    sqlite::Statement update(
        db, "UPDATE scan_poses SET checksum = ?3 WHERE scan_id = ?1 AND command_id = ?2", file);
    update.bind_int(1, record.scan_id).bind_int(2, record.command_id);
    update.bind_int(3, checksum(record)).run();
  }
}

void fill_command_and_layer_checksums(sqlite3* db, const std::string& file) {
  std::vector<std::pair<std::int64_t, std::int64_t>> sums;  // (key, checksum)
  const std::string commands_sql = sql_of({"SELECT ", kCommandColumns, " FROM commands"});
  for (sqlite::Statement commands(db, commands_sql.c_str(), file); commands.step();) {
    const CommandFields record = read_command_fields(commands).first;
    sums.emplace_back(record.id, checksum(record));
  }
  for (const auto& [id, sum] : sums) {
    sqlite::Statement update(db, "UPDATE commands SET checksum = ?2 WHERE id = ?1", file);
    update.bind_int(1, id).bind_int(2, sum).run();
  }
  std::vector<std::pair<LayerFields, std::int64_t>> layers;
  const std::string layers_sql = sql_of({"SELECT ", kLayerColumns, " FROM scan_layers l"});
  for (sqlite::Statement select(db, layers_sql.c_str(), file); select.step();) {
    const LayerFields record = read_layer_fields(select, 0).first;
    layers.emplace_back(record, checksum(record));
  }
  for (const auto& [record, sum] : layers) {
    sqlite::Statement update(
        db,
        "UPDATE scan_layers SET checksum = ?4 WHERE scan_id = ?1 AND name = ?2 AND command_id = ?3",
        file);
    update.bind_int(1, record.scan_id).bind_text(2, record.name).bind_int(3, record.command_id);
    update.bind_int(4, sum).run();
  }
}

}  // namespace

void fill_migrated_checksums(sqlite3* db, const std::string& file) {
  fill_content_digests(db, file);
  fill_scan_and_pose_checksums(db, file);
  fill_command_and_layer_checksums(db, file);
}

}  // namespace scanbench::store
