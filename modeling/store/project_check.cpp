// Project::check: everything `scanbench check` verifies.
#include <sqlite3.h>

#include <vector>

#include "core/errors.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/layer_rows.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/row_checksum.hpp"
#include "modeling/store/sqlite_statement.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::store {
namespace {

void sqlite_checks(sqlite3* db, const std::string& file, std::vector<std::string>& damage) {
  for (sqlite::Statement integrity(db, "PRAGMA integrity_check", file); integrity.step();) {
    const std::string line = integrity.column_text(0);
    if (line != "ok") damage.push_back("database: " + line);
  }
  for (sqlite::Statement keys(db, "PRAGMA foreign_key_check", file); keys.step();) {
    damage.push_back("database: a row of " + keys.column_text(0) + " points to a missing " +
                     keys.column_text(2));
  }
}

std::size_t check_scan_records(sqlite3* db, const std::string& file,
                               std::vector<std::string>& damage) {
  std::size_t checked = 0;
  const std::string sql = sql_of({"SELECT s.id, ", kScanRecordColumns, " FROM scans s"});
  for (sqlite::Statement scans(db, sql.c_str(), file); scans.step(); ++checked) {
    const auto [record, stored] = read_scan_record(scans, 1);
    if (checksum(record) != stored) {
      damage.push_back("scan " + std::to_string(scans.column_int(0)) +
                       ": its record (name, grid, angle model, summary) fails its checksum");
    }
  }
  const std::string poses_sql = sql_of({"SELECT ", kPoseRecordColumns, " FROM scan_poses p"});
  for (sqlite::Statement poses(db, poses_sql.c_str(), file); poses.step(); ++checked) {
    const auto [record, stored] = read_pose_record(poses, 0);
    if (checksum(record) != stored || record.pose.size() != 16 * sizeof(double)) {
      damage.push_back("scan " + std::to_string(record.scan_id) + ": the pose of command " +
                       std::to_string(record.command_id) + " fails its checksum");
    }
  }
  return checked;
}

std::size_t check_commands(sqlite3* db, const std::string& file, std::vector<std::string>& damage) {
  std::size_t checked = 0;
  const std::string sql = sql_of({"SELECT ", kCommandColumns, " FROM commands"});
  for (sqlite::Statement commands(db, sql.c_str(), file); commands.step(); ++checked) {
    const auto [fields, stored] = read_command_fields(commands);
    if (checksum(fields) != stored) {
      damage.push_back("command " + std::to_string(fields.id) + " (" + fields.name +
                       "): its journal entry (settings, result, state) fails its checksum");
    }
  }
  return checked;
}

std::size_t check_layers(sqlite3* db, const std::string& file, std::vector<std::string>& damage) {
  std::size_t checked = 0;
  const std::string sql = sql_of({"SELECT ", kLayerColumns, R"sql(, l.rowid,
  CASE WHEN l.frame IS NULL THEN 'data' ELSE 'frame' END, s.rows, s.columns
FROM scan_layers l JOIN scans s ON s.id = l.scan_id)sql"});
  for (sqlite::Statement layers(db, sql.c_str(), file); layers.step(); ++checked) {
    const auto [fields, stored] = read_layer_fields(layers, 0);
    if (checksum(fields) != stored) {
      damage.push_back("scan " + std::to_string(fields.scan_id) + ", layer " + fields.name +
                       " of command " + std::to_string(fields.command_id) +
                       ": its row (name, type, size, command) fails its checksum");
      continue;
    }
    if (fields.codec != "zstd") continue;  // a removal: no data
    const std::string where = "scan " + std::to_string(fields.scan_id) + ", layer " + fields.name +
                              " of command " + std::to_string(fields.command_id);
    const std::optional<ElementType> type = element_type_from_name(fields.element_type);
    if (!type) {
      damage.push_back(where + ": unknown element type");
      continue;
    }
    const auto rows = static_cast<int>(layers.column_int(9));
    const auto columns = static_cast<int>(layers.column_int(10));
    const std::int64_t pixels = std::int64_t{rows} * columns;
    if (fields.element_count != pixels) {
      damage.push_back(where + ": holds " + std::to_string(fields.element_count) +
                       " elements, the scan has " + std::to_string(pixels) + " pixels");
      continue;
    }
    try {  // a band at a time: a layer may be larger than memory
      check_stored_frame(db, layers.column_int(7), layers.column_text(8).c_str(), rows, columns,
                         *type, BlobContext{file, where});
    } catch (const core::InputError& error) {
      damage.push_back(where + ": " + error.problem());
    }
  }
  return checked;
}

std::size_t check_nodes(sqlite3* db, const std::string& file, std::vector<std::string>& damage) {
  std::size_t checked = 0;
  const std::string sql = sql_of({"SELECT ", kNodeColumns, " FROM object_nodes n"});
  for (sqlite::Statement nodes(db, sql.c_str(), file); nodes.step(); ++checked) {
    const auto [record, stored] = read_node_record(nodes);
    if (checksum(record) != stored) {
      damage.push_back("object node " + std::to_string(record.node_id) +
                       ": its version of command " + std::to_string(record.command_id) +
                       " fails its checksum");
    }
  }
  return checked;
}

std::size_t check_scan_colors(sqlite3* db, const std::string& file,
                              std::vector<std::string>& damage) {
  std::size_t checked = 0;
  for (sqlite::Statement rows(
           db, "SELECT scan_id, command_id, correction, checksum FROM scan_colors", file);
       rows.step(); ++checked) {
    const ScanColorRecord record{rows.column_int(0), rows.column_int(1), rows.column_text(2)};
    if (checksum(record) != rows.column_int(3)) {
      damage.push_back("colour correction of scan " + std::to_string(record.scan_id) +
                       ": its version of command " + std::to_string(record.command_id) +
                       " fails its checksum");
    }
  }
  return checked;
}

std::size_t check_scan_sources(sqlite3* db, const std::string& file,
                               std::vector<std::string>& damage) {
  std::size_t checked = 0;
  for (sqlite::Statement rows(db, "SELECT scan_id, details, checksum FROM scan_sources", file);
       rows.step(); ++checked) {
    const ScanSourceRecord record{rows.column_int(0), rows.column_text(1)};
    if (checksum(record) != rows.column_int(2)) {
      damage.push_back("source of scan " + std::to_string(record.scan_id) + " fails its checksum");
    }
  }
  return checked;
}

std::size_t check_scan_images(sqlite3* db, const std::string& file,
                              std::vector<std::string>& damage) {
  std::size_t checked = 0;
  for (sqlite::Statement rows(db,
                              "SELECT id, created_by, scan_id, description, format, data_crc, "
                              "checksum, data FROM scan_images",
                              file);
       rows.step(); ++checked) {
    ImageRecord record;
    record.created_by = rows.column_int(1);
    if (!rows.is_null(2)) record.scan_id = rows.column_int(2);
    record.description = rows.column_text(3);
    record.format = rows.column_text(4);
    record.data_crc = rows.column_int(5);
    const std::string image = "image " + std::to_string(rows.column_int(0));
    if (checksum(record) != rows.column_int(6)) damage.push_back(image + " fails its checksum");
    if (static_cast<std::int64_t>(crc32_of(std::as_bytes(rows.column_blob(7)))) !=
        record.data_crc) {
      damage.push_back(image + ": its data fails its CRC");
    }
  }
  return checked;
}

}  // namespace

Project::CheckReport Project::check() const {
  CheckReport report;
  sqlite_checks(db(), file_name(), report.damage);
  report.records += check_scan_records(db(), file_name(), report.damage);
  report.records += check_commands(db(), file_name(), report.damage);
  report.records += check_nodes(db(), file_name(), report.damage);
  report.records += check_scan_colors(db(), file_name(), report.damage);
  report.records += check_scan_sources(db(), file_name(), report.damage);
  report.records += check_scan_images(db(), file_name(), report.damage);
  report.layers = check_layers(db(), file_name(), report.damage);
  return report;
}

}  // namespace scanbench::store
