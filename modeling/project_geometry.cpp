// The scan_geometry table (schema version 2): Project::store_geometry and
// Project::load_geometry.
#include <sqlite3.h>

#include <cassert>

#include "core/errors.hpp"
#include "modeling/blob_codec.hpp"
#include "modeling/project.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {
namespace {

constexpr const char* kUpsert = R"sql(
INSERT OR REPLACE INTO scan_geometry
  (scan_id, settings, normals, mixed_pixels, edge_pixels, footprint_m, normal, confidence, flags)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)
)sql";

constexpr const char* kSelect = R"sql(
SELECT g.footprint_m, g.normal, g.confidence, g.flags, s.rows * s.columns
FROM scan_geometry g JOIN scans s ON s.id = g.scan_id WHERE g.scan_id = ?1
)sql";

}  // namespace

std::size_t Project::stored_pixel_count(std::int64_t id) const {
  sqlite::Statement statement(db(), "SELECT rows * columns FROM scans WHERE id = ?1", file_name());
  statement.bind_int(1, id);
  if (!statement.step()) {
    throw core::InputError(file_name(), {}, "no scan with id " + std::to_string(id));
  }
  return static_cast<std::size_t>(statement.column_int(0));
}

void Project::store_geometry(std::int64_t id, const acquisition::GeometryResult& result,
                             const std::string& settings_json) {
  assert(sqlite3_get_autocommit(db()) == 0 && "store_geometry needs an open Transaction");
  const acquisition::ScanGeometry& g = result.geometry;
  [[maybe_unused]] const std::size_t n = stored_pixel_count(id);
  assert(g.footprint_m.size() == n && g.normal.size() == n && g.confidence.size() == n &&
         g.flags.size() == n && "geometry does not match the scan");
  sqlite::Statement statement(db(), kUpsert, file_name());
  statement.bind_int(1, id)
      .bind_text(2, settings_json)
      .bind_int(3, static_cast<std::int64_t>(result.normals))
      .bind_int(4, static_cast<std::int64_t>(result.mixed_pixels))
      .bind_int(5, static_cast<std::int64_t>(result.edge_pixels))
      .bind_blob(6, compress_floats(g.footprint_m))
      .bind_blob(7, compress_vectors(g.normal))
      .bind_blob(8, compress_floats(g.confidence))
      .bind_blob(9, compress_bytes(g.flags))
      .run();
}

std::optional<acquisition::ScanGeometry> Project::load_geometry(std::int64_t id) const {
  sqlite::Statement statement(db(), kSelect, file_name());
  statement.bind_int(1, id);
  if (!statement.step()) return std::nullopt;
  const auto n = static_cast<std::size_t>(statement.column_int(4));
  const auto context = [&](const char* channel) {
    return BlobContext{file_name(), "scan " + std::to_string(id) + ", geometry " + channel};
  };
  acquisition::ScanGeometry g;
  g.footprint_m = decompress_floats(statement.column_blob(0), n, context("footprint_m"));
  g.normal = decompress_vectors(statement.column_blob(1), n, context("normal"));
  g.confidence = decompress_floats(statement.column_blob(2), n, context("confidence"));
  g.flags = decompress_bytes(statement.column_blob(3), n, context("flags"));
  return g;
}

}  // namespace scanbench::modeling
