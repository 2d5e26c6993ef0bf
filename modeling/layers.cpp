// The scan_layers table: versioned per-pixel layers (layers.hpp, project.hpp).
#include "modeling/layers.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <array>
#include <cassert>

#include "core/errors.hpp"
#include "core/memory.hpp"
#include "modeling/blob_codec.hpp"
#include "modeling/project.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {
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
// command, in journal order.
constexpr const char* kSelectCurrent = R"sql(
SELECT l.element_type, l.element_count, l.codec, l.data
FROM scan_layers l JOIN commands c ON c.id = l.command_id
WHERE l.scan_id = ?1 AND l.name = ?2 AND c.state = 'done'
ORDER BY c.seq DESC LIMIT 1)sql";

// The layers whose name fixes their type (layers.hpp).
struct KnownLayer {
  const char* name;
  ElementType type;
};
constexpr std::array<KnownLayer, 10> kKnownLayers = {{{layer::kRange, ElementType::kF32},
                                                      {layer::kValid, ElementType::kU8},
                                                      {layer::kIntensity, ElementType::kF32},
                                                      {layer::kRgb, ElementType::kU8x3},
                                                      {layer::kDirections, ElementType::kF32x3},
                                                      {layer::kFootprint, ElementType::kF32},
                                                      {layer::kNormal, ElementType::kF32x3},
                                                      {layer::kConfidence, ElementType::kF32},
                                                      {layer::kGeometryFlags, ElementType::kU8},
                                                      {layer::kKeep, ElementType::kU8}}};

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

void Project::put_layer(Edit& edit, std::int64_t id, const EncodedLayer& layer) {
  check_edit(edit);
  [[maybe_unused]] const std::size_t n = stored_pixel_count(id, &edit);
  assert(layer.element_count == n && "a layer holds one element per pixel");
  assert(has_its_type(layer) && "a layer named in layers.hpp has the type listed there");
  sqlite::Statement insert(db(), R"sql(
INSERT INTO scan_layers (scan_id, name, command_id, element_type, element_count, codec, data)
VALUES (?1, ?2, ?3, ?4, ?5, 'zstd', ?6)
ON CONFLICT (scan_id, name, command_id) DO UPDATE SET
  element_type = excluded.element_type, element_count = excluded.element_count,
  codec = excluded.codec, data = excluded.data)sql",
                           file_name());
  insert.bind_int(1, id).bind_text(2, layer.name).bind_int(3, edit.command_id());
  insert.bind_text(4, element_type_name(layer.type))
      .bind_int(5, static_cast<std::int64_t>(layer.element_count))
      .bind_blob(6, layer.blob)
      .run();
}

void Project::remove_layer(Edit& edit, std::int64_t id, std::string_view name) {
  check_edit(edit);
  static_cast<void>(stored_pixel_count(id, &edit));  // no such scan: InputError
  const std::vector<std::string> present = layer_names(id);
  if (std::find(present.begin(), present.end(), name) == present.end()) return;
  sqlite::Statement insert(db(), R"sql(
INSERT OR REPLACE INTO scan_layers (scan_id, name, command_id, element_type, element_count, codec,
                                    data)
VALUES (?1, ?2, ?3, 'u8', 0, 'removed', NULL))sql",
                           file_name());
  insert.bind_int(1, id).bind_text(2, name).bind_int(3, edit.command_id()).run();
}

bool Project::read_layer(
    std::int64_t id, std::string_view name, ElementType type,
    const std::function<std::span<std::byte>(std::size_t bytes)>& allocate) const {
  const std::size_t n = stored_pixel_count(id);
  sqlite::Statement select(db(), kSelectCurrent, file_name());
  select.bind_int(1, id).bind_text(2, name);
  if (!select.step() || select.column_text(2) == "removed") return false;
  if (select.column_text(2) != "zstd") damaged(file_name(), id, name, "unknown codec");
  const std::string stored_type = select.column_text(0);
  if (stored_type != element_type_name(type)) {
    damaged(file_name(), id, name,
            "holds " + stored_type + " elements, expected " + element_type_name(type));
  }
  if (select.column_int(1) != static_cast<std::int64_t>(n)) {
    damaged(file_name(), id, name,
            "has " + std::to_string(select.column_int(1)) + " elements, expected " +
                std::to_string(n) + " (one per pixel)");
  }
  const BlobContext context{file_name(),
                            "scan " + std::to_string(id) + ", layer " + std::string(name)};
  // The frame must hold what the grid needs before a buffer is made for it.
  check_blob_size(select.column_blob(3), n * element_size(type), context);
  core::check_memory(n * element_size(type), file_name());
  decompress_into(select.column_blob(3), allocate(n * element_size(type)), context);
  return true;
}

std::vector<std::string> Project::layer_names(std::int64_t id) const {
  sqlite::Statement select(db(), R"sql(
SELECT name FROM (
  SELECT l.name, l.codec, row_number() OVER (PARTITION BY l.name ORDER BY c.seq DESC) AS newest
  FROM scan_layers l JOIN commands c ON c.id = l.command_id
  WHERE l.scan_id = ?1 AND c.state = 'done')
WHERE newest = 1 AND codec != 'removed'
ORDER BY name)sql",
                           file_name());
  select.bind_int(1, id);
  std::vector<std::string> names;
  while (select.step()) names.push_back(select.column_text(0));
  return names;
}

}  // namespace scanbench::modeling
