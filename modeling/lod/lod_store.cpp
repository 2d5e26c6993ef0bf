#include "modeling/lod/lod_store.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

#include <cassert>
#include <cstring>

#include "core/errors.hpp"
#include "modeling/store/sqlite_statement.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::lod {
namespace {

using store::sqlite::Statement;

// "SBLD" in the header's application_id: a store, not a project or another
// application's database.
constexpr std::uint32_t kLodApplicationId = 0x53424c44;
// Node data is read far more often than written: zstd's fastest level
// compresses 40-byte points about 2× and decodes at memory speed.
constexpr int kNodeCompressionLevel = 1;

constexpr const char* kSchema = R"sql(
CREATE TABLE lod_header (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  format INTEGER NOT NULL,
  project_revision INTEGER NOT NULL,
  origin_x REAL NOT NULL, origin_y REAL NOT NULL, origin_z REAL NOT NULL,
  corner_x INTEGER NOT NULL, corner_y INTEGER NOT NULL, corner_z INTEGER NOT NULL,
  edge_bits INTEGER NOT NULL CHECK (edge_bits BETWEEN 7 AND 32),
  max_leaf_points INTEGER NOT NULL CHECK (max_leaf_points >= 1),
  points INTEGER NOT NULL,
  nodes INTEGER NOT NULL);
CREATE TABLE lod_scans (
  point_scan INTEGER PRIMARY KEY CHECK (point_scan BETWEEN 0 AND 65535),
  scan_id INTEGER NOT NULL UNIQUE,
  name TEXT NOT NULL,
  intensity_low REAL NOT NULL,
  intensity_high REAL NOT NULL,
  pose BLOB NOT NULL CHECK (length(pose) = 128));
CREATE TABLE lod_nodes (
  code INTEGER PRIMARY KEY CHECK (code >= 1),
  leaf INTEGER NOT NULL CHECK (leaf IN (0, 1)),
  points_below INTEGER NOT NULL,
  points INTEGER NOT NULL CHECK (points >= 0 AND points <= points_below),
  level_ends BLOB NOT NULL CHECK (length(level_ends) = 36),
  bounds BLOB NOT NULL CHECK (length(bounds) = 24),
  max_radius REAL NOT NULL,
  data BLOB NOT NULL);
)sql";

template <typename T>
std::span<const std::uint8_t> bytes_of(const T* data, std::size_t count) {
  return {reinterpret_cast<const std::uint8_t*>(data), count * sizeof(T)};
}

// Copies a blob column of exactly `count` elements into `out`; false when
// its size differs.
template <typename T>
bool read_blob(const Statement& statement, int column, T* out, std::size_t count) {
  const std::span<const std::uint8_t> blob = statement.column_blob(column);
  if (blob.size() != count * sizeof(T)) return false;
  if (count > 0) std::memcpy(out, blob.data(), blob.size());
  return true;
}

[[noreturn]] void damaged(const std::filesystem::path& file, const std::string& where,
                          const std::string& problem) {
  core::FilePosition position;
  position.detail = where;
  throw core::InputError(file.string(), position, problem);
}

sqlite3* connect(const std::filesystem::path& file, int flags) {
  return store::sqlite::open_connection(file.string(), flags, "opening the level-of-detail store");
}

std::int64_t pragma_int(sqlite3* db, const char* sql, const std::string& file) {
  Statement statement(db, sql, file);
  return statement.step() ? statement.column_int(0) : 0;
}

LodHeader read_header(sqlite3* db, const std::filesystem::path& file) {
  Statement s(db,
              "SELECT format, project_revision, origin_x, origin_y, origin_z, corner_x, corner_y, "
              "corner_z, edge_bits, max_leaf_points, points, nodes FROM lod_header",
              file.string());
  if (!s.step()) damaged(file, "its header", "is missing: the store was never completed");
  if (s.column_int(0) > kLodFormatVersion) {
    damaged(file, "its header",
            "is of format " + std::to_string(s.column_int(0)) +
                ", newer than this scanbench reads (" + std::to_string(kLodFormatVersion) +
                "): run `scanbench lod` to rebuild it");
  }
  LodHeader h;
  h.project_revision = s.column_int(1);
  h.origin = {s.column_double(2), s.column_double(3), s.column_double(4)};
  h.cube.corner = {s.column_int(5), s.column_int(6), s.column_int(7)};
  h.cube.edge_bits = static_cast<int>(s.column_int(8));
  h.octree.max_leaf_points = static_cast<std::size_t>(s.column_int(9));
  h.points = static_cast<std::uint64_t>(s.column_int(10));
  h.nodes = static_cast<std::uint64_t>(s.column_int(11));
  return h;
}

std::vector<LodScan> read_scans(sqlite3* db, const std::filesystem::path& file) {
  Statement s(
      db,
      "SELECT point_scan, scan_id, name, intensity_low, intensity_high, pose FROM lod_scans "
      "ORDER BY point_scan",
      file.string());
  std::vector<LodScan> scans;
  while (s.step()) {
    LodScan scan;
    scan.index = static_cast<std::uint16_t>(s.column_int(0));
    scan.scan_id = s.column_int(1);
    scan.name = s.column_text(2);
    scan.intensity_low = static_cast<float>(s.column_double(3));
    scan.intensity_high = static_cast<float>(s.column_double(4));
    read_blob(s, 5, scan.T_world_scan.matrix().data(), 16);
    scans.push_back(std::move(scan));
  }
  return scans;
}

std::string node_name(const NodeKey& key) {
  return "node " + std::to_string(key.code()) + " (depth " + std::to_string(key.depth) + ")";
}

}  // namespace

std::filesystem::path LodStore::path_for(const std::filesystem::path& project) {
  return std::filesystem::path(project.string() + ".lod");
}

LodStore::LodStore(std::filesystem::path file, sqlite3* db) : file_(std::move(file)), db_(db) {}

LodStore::LodStore(LodStore&& other) noexcept
    : file_(std::move(other.file_)),
      db_(std::exchange(other.db_, nullptr)),
      header_(std::move(other.header_)),
      scans_(std::move(other.scans_)) {}

LodStore& LodStore::operator=(LodStore&& other) noexcept {
  if (this != &other) {
    sqlite3_close(db_);
    file_ = std::move(other.file_);
    db_ = std::exchange(other.db_, nullptr);
    header_ = std::move(other.header_);
    scans_ = std::move(other.scans_);
  }
  return *this;
}

LodStore::~LodStore() {
  sqlite3_close(db_);
}

LodStore LodStore::open(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) {
    damaged(file, "", "is not there: run `scanbench lod` on the project to build it");
  }
  LodStore store(file, connect(file, SQLITE_OPEN_READONLY));
  const std::string name = file.string();
  const auto id = static_cast<std::uint32_t>(pragma_int(store.db_, "PRAGMA application_id", name));
  if (id != kLodApplicationId) {
    damaged(file, "its SQLite header", "is not a scanbench level-of-detail store");
  }
  store.header_ = read_header(store.db_, file);
  store.scans_ = read_scans(store.db_, file);
  return store;
}

std::vector<LodNodeInfo> LodStore::nodes() const {
  Statement s(db_,
              "SELECT code, leaf, points_below, points, level_ends, bounds, max_radius "
              "FROM lod_nodes ORDER BY code",
              file_.string());
  std::vector<LodNodeInfo> nodes;
  while (s.step()) {
    LodNodeInfo node;
    node.key = NodeKey::from_code(static_cast<std::uint64_t>(s.column_int(0)));
    node.leaf = s.column_int(1) != 0;
    node.points_below = static_cast<std::uint64_t>(s.column_int(2));
    node.points = static_cast<std::uint32_t>(s.column_int(3));
    std::array<float, 6> bounds{};
    if (!read_blob(s, 4, node.level_ends.data(), node.level_ends.size()) ||
        !read_blob(s, 5, bounds.data(), bounds.size()) ||
        node.key.depth > header_.cube.max_depth()) {
      damaged(file_, node_name(node.key), "has a damaged description");
    }
    if (node.points > 0) {
      node.bounds = Eigen::AlignedBox3f(Eigen::Vector3f(bounds[0], bounds[1], bounds[2]),
                                        Eigen::Vector3f(bounds[3], bounds[4], bounds[5]));
    }
    node.max_radius_m = static_cast<float>(s.column_double(6));
    nodes.push_back(node);
  }
  return nodes;
}

std::vector<LodPoint> LodStore::read_points(const NodeKey& node) const {
  Statement s(db_, "SELECT points, data FROM lod_nodes WHERE code = ?1", file_.string());
  s.bind_int(1, static_cast<std::int64_t>(node.code()));
  if (!s.step()) damaged(file_, node_name(node), "is missing");
  std::vector<LodPoint> points(static_cast<std::size_t>(s.column_int(0)));
  store::decompress_into(s.column_blob(1), std::as_writable_bytes(std::span<LodPoint>(points)),
                         {file_.string(), node_name(node)});
  return points;
}

LodStoreWriter::LodStoreWriter(const std::filesystem::path& file, const LodHeader& header,
                               const std::vector<LodScan>& scans)
    : file_(file), partial_(file.string() + ".partial"), header_(header) {
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);  // what a crashed build left
  db_ = connect(partial_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  try {
    const std::string name = partial_.string();
    // The partial file is thrown away on any failure: no journal needed.
    store::sqlite::execute(db_, "PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF;", name);
    store::sqlite::execute(db_, kSchema, name);
    store::sqlite::execute(
        db_, ("PRAGMA application_id = " + std::to_string(kLodApplicationId)).c_str(), name);
    store::sqlite::execute(db_, "BEGIN", name);
    for (const LodScan& scan : scans) {
      Statement insert(db_,
                       "INSERT INTO lod_scans (point_scan, scan_id, name, intensity_low, "
                       "intensity_high, pose) VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                       name);
      insert.bind_int(1, scan.index)
          .bind_int(2, scan.scan_id)
          .bind_text(3, scan.name)
          .bind_double(4, scan.intensity_low)
          .bind_double(5, scan.intensity_high)
          .bind_blob(6, bytes_of(scan.T_world_scan.matrix().data(), 16))
          .run();
    }
  } catch (...) {
    sqlite3_close(db_);
    std::error_code ignored_too;
    std::filesystem::remove(partial_, ignored_too);
    throw;
  }
}

LodStoreWriter::~LodStoreWriter() {
  if (committed_) return;
  sqlite3_close(db_);
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
}

void LodStoreWriter::put(const BuiltNode& node) {
  assert(!committed_ && "put before commit");
  const std::string name = partial_.string();
  // Bounds and the largest radius, from the points' quanta.
  const Eigen::AlignedBox3d box = header_.cube.node_box(node.key);
  Eigen::AlignedBox3f bounds;
  float max_radius = 0.0f;
  for (const LodPoint& p : node.points) {
    const Eigen::Vector3d offset(p.offset[0], p.offset[1], p.offset[2]);
    bounds.extend((box.min() + offset * kQuantumM).cast<float>());
    max_radius = std::max({max_radius, from_half(p.radii[0]), from_half(p.radii[1])});
  }
  const std::array<float, 6> corners =
      bounds.isEmpty() ? std::array<float, 6>{}
                       : std::array<float, 6>{bounds.min().x(), bounds.min().y(), bounds.min().z(),
                                              bounds.max().x(), bounds.max().y(), bounds.max().z()};
  const std::vector<std::uint8_t> data =
      store::compress(std::as_bytes(std::span<const LodPoint>(node.points)), kNodeCompressionLevel);
  const std::lock_guard lock(mutex_);
  Statement insert(db_,
                   "INSERT INTO lod_nodes (code, leaf, points_below, points, level_ends, bounds, "
                   "max_radius, data) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
                   name);
  insert.bind_int(1, static_cast<std::int64_t>(node.key.code()))
      .bind_int(2, node.leaf ? 1 : 0)
      .bind_int(3, static_cast<std::int64_t>(node.points_below))
      .bind_int(4, static_cast<std::int64_t>(node.points.size()))
      .bind_blob(5, bytes_of(node.level_ends.data(), node.level_ends.size()))
      .bind_blob(6, bytes_of(corners.data(), corners.size()))
      .bind_double(7, max_radius)
      .bind_blob(8, data)
      .run();
  points_ += node.points.size();
  ++nodes_;
}

void LodStoreWriter::commit() {
  assert(!committed_ && "one commit");
  const std::string name = partial_.string();
  {
    Statement header(db_,
                     "INSERT INTO lod_header (id, format, project_revision, origin_x, origin_y, "
                     "origin_z, corner_x, corner_y, corner_z, edge_bits, max_leaf_points, points, "
                     "nodes) VALUES (1, ?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)",
                     name);
    header.bind_int(1, kLodFormatVersion)
        .bind_int(2, header_.project_revision)
        .bind_double(3, header_.origin.x())
        .bind_double(4, header_.origin.y())
        .bind_double(5, header_.origin.z())
        .bind_int(6, header_.cube.corner[0])
        .bind_int(7, header_.cube.corner[1])
        .bind_int(8, header_.cube.corner[2])
        .bind_int(9, header_.cube.edge_bits)
        .bind_int(10, static_cast<std::int64_t>(header_.octree.max_leaf_points))
        .bind_int(11, static_cast<std::int64_t>(points_))
        .bind_int(12, static_cast<std::int64_t>(nodes_))
        .run();
  }  // finalized: a connection with a statement open does not close
  store::sqlite::execute(db_, "COMMIT", name);
  const int code = sqlite3_close(db_);
  db_ = nullptr;
  if (code != SQLITE_OK) store::sqlite::throw_error(nullptr, code, name, "closing the store");
  // Durable before it replaces the old store: a crash then leaves one of them.
  const int fd = ::open(partial_.c_str(), O_RDONLY);
  const bool synced = fd >= 0 && ::fsync(fd) == 0;
  if (fd >= 0) ::close(fd);
  std::error_code error;
  if (synced) std::filesystem::rename(partial_, file_, error);
  if (!synced || error) {
    core::FilePosition position;
    position.detail = "replacing the level-of-detail store";
    throw core::RuntimeFailure(file_.string(), position,
                               error ? error.message() : "the new store could not be made durable");
  }
  committed_ = true;
}

}  // namespace scanbench::lod
