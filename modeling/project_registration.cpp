// The tables of schema version 3: registration_runs (Project::store_registration,
// latest_registration_report) and merge_masks (store_keep_mask, load_keep_mask,
// clear_keep_masks).
#include <sqlite3.h>

#include <cassert>

#include "core/errors.hpp"
#include "modeling/blob_codec.hpp"
#include "modeling/project.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {
void Project::store_registration(const std::string& settings_json, const std::string& report_json) {
  assert(sqlite3_get_autocommit(db()) == 0 && "store_registration needs an open Transaction");
  sqlite::Statement insert(db(), "INSERT INTO registration_runs (settings, report) VALUES (?1, ?2)",
                           file_name());
  insert.bind_text(1, settings_json).bind_text(2, report_json).run();
}

std::optional<std::string> Project::latest_registration_report() const {
  sqlite::Statement select(db(), "SELECT report FROM registration_runs ORDER BY id DESC LIMIT 1",
                           file_name());
  if (!select.step()) return std::nullopt;
  return select.column_text(0);
}

void Project::store_keep_mask(std::int64_t id, std::span<const std::uint8_t> keep,
                              const std::string& settings_json) {
  assert(sqlite3_get_autocommit(db()) == 0 && "store_keep_mask needs an open Transaction");
  [[maybe_unused]] const std::size_t n = stored_pixel_count(id);
  assert(keep.size() == n && "keep mask does not match the scan");
  std::int64_t kept = 0;
  for (const std::uint8_t k : keep) kept += k != 0;
  sqlite::Statement upsert(db(), R"sql(
INSERT OR REPLACE INTO merge_masks (scan_id, settings, kept_points, keep) VALUES (?1, ?2, ?3, ?4)
)sql",
                           file_name());
  upsert.bind_int(1, id)
      .bind_text(2, settings_json)
      .bind_int(3, kept)
      .bind_blob(4, compress_bytes(keep))
      .run();
}

std::optional<std::vector<std::uint8_t>> Project::load_keep_mask(std::int64_t id) const {
  sqlite::Statement select(db(), R"sql(
SELECT m.keep, s.rows * s.columns FROM merge_masks m JOIN scans s ON s.id = m.scan_id
WHERE m.scan_id = ?1)sql",
                           file_name());
  select.bind_int(1, id);
  if (!select.step()) return std::nullopt;
  const auto n = static_cast<std::size_t>(select.column_int(1));
  return decompress_bytes(select.column_blob(0), n,
                          BlobContext{file_name(), "scan " + std::to_string(id) + ", keep mask"});
}

void Project::clear_keep_masks() {
  assert(sqlite3_get_autocommit(db()) == 0 && "clear_keep_masks needs an open Transaction");
  sqlite::execute(db(), "DELETE FROM merge_masks", file_name());
}

}  // namespace scanbench::modeling
