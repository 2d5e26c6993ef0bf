// The scan_layers table: versioned per-pixel layers (layer_store.hpp, project.hpp).
#include "modeling/store/layer_store.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <memory>

#include "core/errors.hpp"
#include "core/memory.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/layer_rows.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/sqlite_statement.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::store {
namespace {

struct TypeInfo {
  ElementType type;
  const char* name;
  std::size_t size;
};

constexpr std::array<TypeInfo, 5> kTypes = {{{ElementType::kU8, "u8", 1},
                                             {ElementType::kU8x3, "u8x3", 3},
                                             {ElementType::kU32, "u32", 4},
                                             {ElementType::kF32, "f32", 4},
                                             {ElementType::kF32x3, "f32x3", 12}}};

const TypeInfo& info(ElementType type) {
  for (const TypeInfo& t : kTypes) {
    if (t.type == type) return t;
  }
  assert(false && "unknown ElementType");
  return kTypes[0];
}

// The current version of layer (scan, name): the row of the newest done
// command, in journal order. The newest is picked without the data column,
// and then its row read by key: sorting the rows with their data would copy
// each version's data through a temporary b-tree (a temporary file for a
// layer of megabytes) on every read.
// `data` names what is selected after the layer's columns and its rowid.
std::string select_current(const char* data) {
  return sql_of({"SELECT ", kLayerColumns, ", l.rowid, ", data, R"sql(
FROM scan_layers l
WHERE l.scan_id = ?1 AND l.name = ?2 AND l.command_id = (
  SELECT k.command_id FROM scan_layers k JOIN commands c ON c.id = k.command_id
  WHERE k.scan_id = ?1 AND k.name = ?2 AND c.state = 'done'
  ORDER BY c.seq DESC LIMIT 1))sql"});
}
// With the frame, wherever it is stored (schema.cpp, version 10).
const std::string kSelectCurrent = select_current("coalesce(l.frame, l.data)");
// With the column that holds the frame, "frame" or "data", not the frame.
const std::string kSelectCurrentPlace =
    select_current("CASE WHEN l.frame IS NULL THEN 'data' ELSE 'frame' END");

// The layers whose name fixes their type (layer_store.hpp).
struct KnownLayer {
  const char* name;
  ElementType type;
};
constexpr std::array<KnownLayer, 15> kKnownLayers = {
    {{layer::kRange, ElementType::kF32},
     {layer::kValid, ElementType::kU8},
     {layer::kIntensity, ElementType::kF32},
     {layer::kRgb, ElementType::kU8x3},
     {layer::kDirections, ElementType::kF32x3},
     {layer::kRecordedNormal, ElementType::kF32x3},
     {layer::kRecordedFootprint, ElementType::kF32},
     {layer::kFootprint, ElementType::kF32},
     {layer::kNormal, ElementType::kF32x3},
     {layer::kConfidence, ElementType::kF32},
     {layer::kGeometryFlags, ElementType::kU8},
     {layer::kKeep, ElementType::kU8},
     {layer::kSelection, ElementType::kU8},
     {layer::kMembership, ElementType::kU32},
     {layer::kCarried, ElementType::kU8}}};

[[maybe_unused]] bool has_its_type(const EncodedLayer& layer) {
  for (const KnownLayer& known : kKnownLayers) {
    if (layer.name == known.name) return layer.type == known.type;
  }
  return true;
}

[[noreturn]] void damaged(const std::string& file, std::int64_t id, std::string_view name,
                          const std::string& problem) {
  core::FilePosition position;
  position.detail = "scan " + std::to_string(id) + ", layer " + std::string(name);
  throw core::InputError(file, position, "project is damaged: " + problem);
}

}  // namespace

const char* element_type_name(ElementType type) {
  return info(type).name;
}

std::optional<ElementType> element_type_from_name(std::string_view name) {
  for (const TypeInfo& t : kTypes) {
    if (name == t.name) return t.type;
  }
  return std::nullopt;
}

std::size_t element_size(ElementType type) {
  return info(type).size;
}

EncodedLayer encode_layer_bytes(std::string name, ElementType type,
                                std::span<const std::byte> bytes) {
  assert(bytes.size() % element_size(type) == 0 && "a layer holds whole elements");
  EncodedLayer layer;
  layer.name = std::move(name);
  layer.type = type;
  layer.element_count = bytes.size() / element_size(type);
  layer.blob = compress(bytes);
  return layer;
}

namespace {

// Writes (or replaces, within one command) the row of a layer version, with
// its checksum; `blob` empty for a removal.
// With `frame_bytes`, the frame goes in the column `frame`, last in the
// row, as that many zero bytes to be written in place, and `data` is empty.
void write_layer_row(sqlite3* db, const std::string& file, const LayerFields& fields,
                     std::span<const std::uint8_t> blob,
                     std::optional<std::uint64_t> frame_bytes = std::nullopt) {
  sqlite::Statement insert(db, R"sql(
INSERT OR REPLACE INTO scan_layers (scan_id, name, command_id, element_type, element_count, codec,
                                    data, checksum, frame)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9))sql",
                           file);
  insert.bind_int(1, fields.scan_id).bind_text(2, fields.name).bind_int(3, fields.command_id);
  insert.bind_text(4, fields.element_type).bind_int(5, fields.element_count);
  insert.bind_text(6, fields.codec);
  if (fields.codec == "removed") {
    insert.bind_null(7).bind_null(9);
  } else if (frame_bytes) {
    insert.bind_blob(7, {}).bind_zeroblob(9, *frame_bytes);
  } else {
    insert.bind_blob(7, blob).bind_null(9);
  }
  insert.bind_int(8, checksum(fields)).run();
}

// A layer row read back, refused unless it passes its checksum.
LayerFields verified(const sqlite::Statement& row, const std::string& file) {
  auto [fields, stored] = read_layer_fields(row, 0);
  if (checksum(fields) != stored) {
    damaged(file, fields.scan_id, fields.name,
            "the layer's row fails its checksum (changed outside scanbench?)");
  }
  return std::move(fields);
}

}  // namespace

void Project::put_layer(Edit& edit, std::int64_t id, const EncodedLayer& layer) {
  check_edit(edit);
  [[maybe_unused]] const std::size_t n = stored_pixel_count(id, &edit);
  assert(layer.element_count == n && "a layer holds one element per pixel");
  assert(has_its_type(layer) && "a layer named in layer_store.hpp has the type listed there");
  write_layer_row(db(), file_name(),
                  {id, layer.name, edit.command_id(), element_type_name(layer.type),
                   static_cast<std::int64_t>(layer.element_count), "zstd"},
                  layer.blob);
}

void Project::remove_layer(Edit& edit, std::int64_t id, std::string_view name) {
  check_edit(edit);
  static_cast<void>(stored_pixel_count(id, &edit));  // no such scan: InputError
  const std::vector<std::string> present = layer_names(id);
  if (std::find(present.begin(), present.end(), name) == present.end()) return;
  write_layer_row(db(), file_name(), {id, std::string(name), edit.command_id(), "u8", 0, "removed"},
                  {});
}

namespace {

// The current version of a layer, its row verified and its fields checked
// against the scan's pixel count and the `expected` type.
struct CurrentLayer {
  ElementType type;
  std::int64_t rowid;
  BlobContext context;
};

std::optional<CurrentLayer> current_layer(const sqlite::Statement& select, const std::string& file,
                                          std::int64_t id, std::string_view name, std::size_t n,
                                          std::optional<ElementType> expected) {
  const LayerFields fields = verified(select, file);
  if (fields.codec == "removed") return std::nullopt;
  if (fields.codec != "zstd") damaged(file, id, name, "unknown codec");
  const std::optional<ElementType> stored = element_type_from_name(fields.element_type);
  if (!stored) damaged(file, id, name, "unknown element type " + fields.element_type);
  if (expected && *stored != *expected) {
    damaged(file, id, name,
            "holds " + fields.element_type + " elements, expected " + element_type_name(*expected));
  }
  if (fields.element_count != static_cast<std::int64_t>(n)) {
    damaged(file, id, name,
            "has " + std::to_string(fields.element_count) + " elements, expected " +
                std::to_string(n) + " (one per pixel)");
  }
  return CurrentLayer{*stored,
                      select.column_int(7),
                      {file, "scan " + std::to_string(id) + ", layer " + std::string(name)}};
}

}  // namespace

bool Project::read_layer(
    std::int64_t id, std::string_view name, std::optional<ElementType> expected,
    const std::function<std::span<std::byte>(std::size_t bytes)>& allocate) const {
  const std::size_t n = stored_pixel_count(id);
  sqlite::Statement select(db(), kSelectCurrent.c_str(), file_name());
  select.bind_int(1, id).bind_text(2, name);
  if (!select.step()) return false;
  const std::optional<CurrentLayer> layer =
      current_layer(select, file_name(), id, name, n, expected);
  if (!layer) return false;
  const std::size_t bytes = n * element_size(layer->type);
  // The frame must hold what the grid needs before a buffer is made for it.
  const std::span<const std::uint8_t> blob = select.column_blob(8);
  check_blob_size(blob, bytes, layer->context);
  core::check_memory(bytes, file_name());
  decompress_into(blob, allocate(bytes), layer->context);
  return true;
}

std::optional<LayerRowReader> Project::open_layer_rows(std::int64_t id, std::string_view name,
                                                       std::optional<ElementType> expected) const {
  const acquisition::ScanSummary grid = current_summary(id).summary;
  sqlite::Statement select(db(), kSelectCurrentPlace.c_str(), file_name());
  select.bind_int(1, id).bind_text(2, name);
  if (!select.step()) return std::nullopt;
  const std::optional<CurrentLayer> layer = current_layer(
      select, file_name(), id, name,
      static_cast<std::size_t>(grid.rows) * static_cast<std::size_t>(grid.columns), expected);
  if (!layer) return std::nullopt;
  return LayerRowReader::open_blob(db(), layer->rowid, select.column_text(8).c_str(), grid.rows,
                                   grid.columns, layer->type, layer->context);
}

void Project::put_layer(Edit& edit, std::int64_t id, const LayerRowWriter& layer) {
  check_edit(edit);
  assert(layer.complete() && "every row written");
  [[maybe_unused]] const std::size_t n = stored_pixel_count(id, &edit);
  assert(static_cast<std::size_t>(layer.rows()) * static_cast<std::size_t>(layer.columns()) == n &&
         "a layer holds one element per pixel");
  [[maybe_unused]] const EncodedLayer described{layer.name(), layer.type(), n, {}};
  assert(has_its_type(described) && "a layer named in layer_store.hpp has the type listed there");
  const std::string where = "scan " + std::to_string(id) + ", layer " + layer.name();
  // A blob over SQLite's limit (1 GB unless built otherwise) cannot be
  // stored: said before anything is, naming the layer.
  const auto limit = static_cast<std::uint64_t>(sqlite3_limit(db(), SQLITE_LIMIT_LENGTH, -1));
  if (layer.compressed_bytes() > limit) {
    core::FilePosition position;
    position.detail = where;
    throw core::InputError(file_name(), position,
                           "the layer takes " + std::to_string(layer.compressed_bytes()) +
                               " bytes compressed, more than a project can store in one piece (" +
                               std::to_string(limit) + "): the scan is too large");
  }
  const LayerFields fields{id,
                           layer.name(),
                           edit.command_id(),
                           element_type_name(layer.type()),
                           static_cast<std::int64_t>(n),
                           "zstd"};
  write_layer_row(db(), file_name(), fields, {}, layer.compressed_bytes());
  sqlite3_blob* blob = nullptr;
  const int code = sqlite3_blob_open(db(), "main", "scan_layers", "frame",
                                     sqlite3_last_insert_rowid(db()), 1, &blob);
  if (code != SQLITE_OK) sqlite::throw_error(db(), code, file_name(), where);
  const std::unique_ptr<sqlite3_blob, decltype(&sqlite3_blob_close)> closing(blob,
                                                                             &sqlite3_blob_close);
  std::uint64_t offset = 0;
  layer.for_each_piece([&](std::span<const std::byte> piece) {
    const int written = sqlite3_blob_write(blob, piece.data(), static_cast<int>(piece.size()),
                                           static_cast<int>(offset));
    if (written != SQLITE_OK) sqlite::throw_error(db(), written, file_name(), where);
    offset += piece.size();
  });
}

void Project::verify_current_layer(std::int64_t id, std::string_view name) const {
  // A band at a time: a layer may be larger than memory.
  if (std::optional<LayerRowReader> rows = open_layer_rows(id, name, std::nullopt))
    rows->read_rest();
}

std::optional<std::string> Project::layer_fingerprint(std::int64_t id,
                                                      std::string_view name) const {
  sqlite::Statement select(db(), kSelectCurrentPlace.c_str(), file_name());
  select.bind_int(1, id).bind_text(2, name);
  if (!select.step()) return std::nullopt;
  const LayerFields fields = verified(select, file_name());
  if (fields.codec == "removed") return std::nullopt;
  const std::string where = "scan " + std::to_string(id) + ", layer " + std::string(name);
  sqlite3_blob* blob = nullptr;
  const int code = sqlite3_blob_open(db(), "main", "scan_layers", select.column_text(8).c_str(),
                                     select.column_int(7), 0, &blob);
  if (code != SQLITE_OK) sqlite::throw_error(db(), code, file_name(), where);
  const std::unique_ptr<sqlite3_blob, decltype(&sqlite3_blob_close)> closing(blob,
                                                                             &sqlite3_blob_close);
  const int bytes = sqlite3_blob_bytes(blob);
  std::array<std::uint8_t, 4> checksum{};
  if (bytes >= 4) {
    const int read = sqlite3_blob_read(blob, checksum.data(), 4, bytes - 4);
    if (read != SQLITE_OK) sqlite::throw_error(db(), read, file_name(), where);
  }
  std::string hex;
  for (const std::uint8_t b : checksum) {
    constexpr const char* kDigits = "0123456789abcdef";
    hex += kDigits[b >> 4];
    hex += kDigits[b & 15];
  }
  return fields.element_type + "/" + std::to_string(fields.element_count) + "/" +
         std::to_string(bytes) + "/" + hex;
}

std::vector<std::string> Project::layer_names(std::int64_t id) const {
  const std::string sql = sql_of({R"sql(
SELECT )sql",
                                  kLayerColumns, R"sql( FROM (
  SELECT )sql",
                                  kLayerColumns, R"sql(,
    row_number() OVER (PARTITION BY l.name ORDER BY c.seq DESC) AS newest
  FROM scan_layers l JOIN commands c ON c.id = l.command_id
  WHERE l.scan_id = ?1 AND c.state = 'done') l
WHERE newest = 1
ORDER BY name)sql"});
  sqlite::Statement select(db(), sql.c_str(), file_name());
  select.bind_int(1, id);
  std::vector<std::string> names;
  while (select.step()) {
    const LayerFields fields = verified(select, file_name());
    if (fields.codec != "removed") names.push_back(fields.name);
  }
  return names;
}

}  // namespace scanbench::store
