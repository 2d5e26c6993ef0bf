// The scan_colors table: Project::scan_color_corrections and
// put_scan_color_correction. Versioned like poses (project.hpp),
// checksummed like every record (checksummed_rows.hpp).
#include <sqlite3.h>

#include <stdexcept>

#include "core/errors.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store {

namespace {

// Each live scan's row of the newest done command that wrote it.
constexpr const char* kSelectCurrent = R"sql(
SELECT k.scan_id, k.command_id, k.correction, k.checksum
FROM scan_colors k JOIN scans s ON s.id = k.scan_id
WHERE (SELECT state FROM commands WHERE id = s.created_by) = 'done'
  AND k.command_id = (SELECT q.command_id FROM scan_colors q JOIN commands c ON c.id = q.command_id
                      WHERE q.scan_id = k.scan_id AND c.state = 'done'
                      ORDER BY c.seq DESC LIMIT 1)
ORDER BY k.scan_id)sql";

[[noreturn]] void damaged(const std::string& file, std::int64_t scan_id,
                          const std::string& problem) {
  core::FilePosition position;
  position.detail = "colour correction of scan " + std::to_string(scan_id);
  throw core::InputError(file, position, "project is damaged: " + problem);
}

}  // namespace

std::map<std::int64_t, ScanColorCorrection> Project::scan_color_corrections() const {
  std::map<std::int64_t, ScanColorCorrection> out;
  for (sqlite::Statement select(db(), kSelectCurrent, file_name()); select.step();) {
    ScanColorRecord record;
    record.scan_id = select.column_int(0);
    record.command_id = select.column_int(1);
    record.correction = select.column_text(2);
    if (checksum(record) != select.column_int(3))
      damaged(file_name(), record.scan_id,
              "the row fails its checksum (changed outside scanbench?)");
    try {
      out[record.scan_id] = scan_color_correction_from_json(record.correction);
    } catch (const std::invalid_argument& e) {
      damaged(file_name(), record.scan_id, e.what());
    }
  }
  return out;
}

void Project::put_scan_color_correction(Edit& edit, std::int64_t id,
                                        const ScanColorCorrection& correction) {
  check_edit(edit);
  stored_pixel_count(id, &edit);  // throws when there is no such scan
  ScanColorRecord record{id, edit.command_id(), to_json(correction)};
  sqlite::Statement insert(db(),
                           "INSERT OR REPLACE INTO scan_colors (scan_id, command_id, correction, "
                           "checksum) VALUES (?1, ?2, ?3, ?4)",
                           file_name());
  insert.bind_int(1, record.scan_id).bind_int(2, record.command_id).bind_text(3, record.correction);
  insert.bind_int(4, checksum(record)).run();
}

}  // namespace scanbench::store
