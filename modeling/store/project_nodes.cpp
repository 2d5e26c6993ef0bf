// The object_nodes table: Project::object_tree, object_nodes, nodes_named,
// new_node_id, put_node, remove_node. Versioned like poses (project.hpp),
// checksummed like every record (checksummed_rows.hpp); the connection keeps the
// tree between commands (object_tree_cache.hpp).
#include <sqlite3.h>

#include <cassert>
#include <cmath>
#include <map>
#include <stdexcept>

#include "core/errors.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/object_tree_cache.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store {

namespace {

// Each node's row of the newest done command that wrote it, live or not.
constexpr const char* kNewestVersion = R"sql(
WHERE n.command_id = (SELECT q.command_id FROM object_nodes q JOIN commands c ON c.id = q.command_id
                      WHERE q.node_id = n.node_id AND c.state = 'done'
                      ORDER BY c.seq DESC LIMIT 1))sql";
const std::string kSelectCurrent = sql_of(
    {"SELECT ", kNodeColumns, " FROM object_nodes n", kNewestVersion, " ORDER BY n.node_id"});
// The same, of one node (?1).
const std::string kSelectCurrentOne = sql_of(
    {"SELECT ", kNodeColumns, " FROM object_nodes n", kNewestVersion, " AND n.node_id = ?1"});

constexpr const char* kInsert = R"sql(
INSERT OR REPLACE INTO object_nodes (node_id, command_id, live, name, kind, parent, hidden, points,
                                     mean_footprint_m, bbox_min_x, bbox_min_y, bbox_min_z,
                                     bbox_max_x, bbox_max_y, bbox_max_z, color_edit, checksum)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17))sql";

NodeRecord record_of(const ObjectNode& node, std::int64_t command_id, bool live) {
  NodeRecord r;
  r.node_id = node.id;
  r.command_id = command_id;
  r.live = live ? 1 : 0;
  r.name = node.name;
  r.kind = node.kind == NodeKind::kGroup ? "group" : "object";
  r.parent = node.parent;
  r.hidden = node.hidden ? 1 : 0;
  r.points = node.points;
  r.mean_footprint_m = node.mean_footprint_m;
  if (node.bbox_world) {
    for (int k = 0; k < 3; ++k) {
      r.bbox[static_cast<std::size_t>(k)] = node.bbox_world->min()[k];
      r.bbox[static_cast<std::size_t>(k + 3)] = node.bbox_world->max()[k];
    }
  }
  r.color_edit = to_json(node.color);
  return r;
}

[[noreturn]] void damaged(const std::string& file, std::int64_t id, const std::string& problem) {
  core::FilePosition position;
  position.detail = "object node " + std::to_string(id);
  throw core::InputError(file, position, "project is damaged: " + problem);
}

ObjectNode node_of(const NodeRecord& r, const std::string& file) {
  ObjectNode node;
  node.id = r.node_id;
  node.name = r.name;
  if (r.kind != "group" && r.kind != "object") damaged(file, r.node_id, "unknown node kind");
  node.kind = r.kind == "group" ? NodeKind::kGroup : NodeKind::kObject;
  node.parent = r.parent;
  node.hidden = r.hidden != 0;
  node.points = r.points;
  node.mean_footprint_m = r.mean_footprint_m;
  if (r.bbox[0]) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) {
      const auto& low = r.bbox[static_cast<std::size_t>(k)];
      const auto& high = r.bbox[static_cast<std::size_t>(k + 3)];
      if (!low || !high) damaged(file, r.node_id, "incomplete bounding box");
      box.min()[k] = *low;
      box.max()[k] = *high;
    }
    node.bbox_world = box;
  }
  try {
    node.color = color_edit_from_json(r.color_edit);
  } catch (const std::invalid_argument& e) {
    damaged(file, r.node_id, std::string("bad colour edit: ") + e.what());
  }
  return node;
}

// Reads the node of `row` (a statement selecting kNodeColumns) into
// `node`, refused when it fails its checksum; false for a deleted one.
bool verified_node(const sqlite::Statement& row, const std::string& file, ObjectNode& node) {
  const auto [record, stored] = read_node_record(row);
  if (checksum(record) != stored)
    damaged(file, record.node_id, "the node's row fails its checksum (changed outside scanbench?)");
  if (!record.live) return false;
  node = node_of(record, file);
  return true;
}

void write(sqlite3* db, const std::string& file, const NodeRecord& r) {
  sqlite::Statement insert(db, kInsert, file);
  insert.bind_int(1, r.node_id).bind_int(2, r.command_id).bind_int(3, r.live);
  insert.bind_text(4, r.name).bind_text(5, r.kind);
  if (r.parent) {
    insert.bind_int(6, *r.parent);
  } else {
    insert.bind_null(6);
  }
  insert.bind_int(7, r.hidden).bind_int(8, r.points).bind_optional_double(9, r.mean_footprint_m);
  for (int k = 0; k < 6; ++k)
    insert.bind_optional_double(10 + k, r.bbox[static_cast<std::size_t>(k)]);
  insert.bind_text(16, r.color_edit).bind_int(17, checksum(r)).run();
}

}  // namespace

std::map<std::int64_t, ObjectNode> Project::read_tree() const {
  std::map<std::int64_t, ObjectNode> tree;
  for (sqlite::Statement select(db(), kSelectCurrent.c_str(), file_name()); select.step();) {
    ObjectNode node;
    if (verified_node(select, file_name(), node)) tree.emplace(node.id, std::move(node));
  }
  return tree;
}

const std::map<std::int64_t, ObjectNode>* Project::current_tree() const {
  ObjectTreeCache& cache = connection_->tree;
  if (connection_->edit) return nullptr;
  const std::int64_t now = revision();
  if (cache.at(now) == nullptr) cache.remember(now, read_tree());
  return cache.at(now);
}

std::map<std::int64_t, ObjectNode> Project::object_tree() const {
  const std::map<std::int64_t, ObjectNode>* tree = current_tree();
  return tree != nullptr ? *tree : read_tree();
}

std::vector<std::int64_t> Project::nodes_named(std::string_view name) const {
  std::vector<std::int64_t> ids;
  const auto collect = [&](const std::map<std::int64_t, ObjectNode>& tree) {
    for (const auto& [id, node] : tree)
      if (node.name == name) ids.push_back(id);
  };
  if (const std::map<std::int64_t, ObjectNode>* tree = current_tree()) {
    collect(*tree);
  } else {
    collect(read_tree());
  }
  return ids;
}

std::vector<ObjectNode> Project::object_nodes() const {
  std::vector<ObjectNode> nodes;
  for (auto& [id, node] : object_tree()) nodes.push_back(std::move(node));
  return nodes;
}

std::int64_t Project::new_node_id() const {
  sqlite::Statement select(db(), "SELECT coalesce(max(node_id), 0) + 1 FROM object_nodes",
                           file_name());
  select.step();
  return select.column_int(0);
}

void Project::put_node(Edit& edit, const ObjectNode& node) {
  check_edit(edit);
  assert(node.id > 0 && node.id < kDeletedPoints && "node ids fit a membership layer");
  assert(node.parent != node.id && "a node is not its own parent");
  assert(node.points >= 0 && "a point count is not negative");
  assert((!node.mean_footprint_m || std::isfinite(*node.mean_footprint_m)) && "finite footprint");
  assert(check_color_edit(node.color).empty() && "a sound colour edit");
  assert((!node.bbox_world ||
          (node.bbox_world->min().allFinite() && node.bbox_world->max().allFinite())) &&
         "finite bounding box");
  write(db(), file_name(), record_of(node, edit.command_id(), true));
  connection_->tree.note_write(node.id, node);
}

void Project::remove_node(Edit& edit, std::int64_t id) {
  check_edit(edit);
  sqlite::Statement select(db(), kSelectCurrentOne.c_str(), file_name());
  select.bind_int(1, id);
  ObjectNode node;
  if (!select.step() || !verified_node(select, file_name(), node)) return;
  write(db(), file_name(), record_of(node, edit.command_id(), false));
  connection_->tree.note_write(id, std::nullopt);
}

}  // namespace scanbench::store
