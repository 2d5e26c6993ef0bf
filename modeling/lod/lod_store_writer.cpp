#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>

#include "core/errors.hpp"
#include "core/radix_sort.hpp"
#include "modeling/lod/lod_schema.hpp"
#include "modeling/lod/lod_store.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::lod {
namespace {

using schema::bytes_of;
using store::sqlite::Statement;

void remove_stale_partials(const std::filesystem::path& file) {
  const std::string prefix = file.filename().string() + ".partial-";
  std::error_code error;
  const std::filesystem::path folder =
      file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(prefix)) continue;
    const std::string pid = name.substr(prefix.size());
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (std::filesystem::exists("/proc/" + pid, error)) continue;
    std::filesystem::remove(entry.path(), error);
  }
}

// Makes a rename in `folder` durable (best effort: a folder that cannot be
// opened keeps the rename in the page cache until the system writes it).
void sync_folder(const std::filesystem::path& file) {
  const std::filesystem::path folder =
      file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

namespace schema {

EncodedNode encode_node(const OctreeCube& cube, const std::vector<LodScan>& scans,
                        const BuiltNode& node) {
  EncodedNode out;
  out.key = node.key;
  out.leaf = node.leaf;
  out.points_below = node.points_below;
  out.points = node.points.size();
  out.level_ends = node.level_ends;
  // Bounds and the largest radius, from the points' quanta.
  const Eigen::AlignedBox3d box = cube.node_box(node.key);
  Eigen::AlignedBox3f bounds;
  for (const LodPoint& p : node.points) {
    const Eigen::Vector3d offset(p.offset[0], p.offset[1], p.offset[2]);
    bounds.extend((box.min() + offset * kQuantumM).cast<float>());
    out.max_radius = std::max({out.max_radius, from_half(p.radii[0]), from_half(p.radii[1])});
  }
  if (!bounds.isEmpty()) {
    out.bounds = {bounds.min().x(), bounds.min().y(), bounds.min().z(),
                  bounds.max().x(), bounds.max().y(), bounds.max().z()};
  }
  out.data =
      store::compress(std::as_bytes(std::span<const LodPoint>(node.points)), kNodeCompressionLevel);
  std::vector<std::uint64_t> tiles, scratch;
  tiles.reserve(node.points.size());
  for (const LodPoint& p : node.points) tiles.push_back(tile_of(scans.at(p.scan), p.pixel));
  core::radix_sort(tiles, scratch, 64, [](std::uint64_t t) { return t; });
  tiles.erase(std::unique(tiles.begin(), tiles.end()), tiles.end());
  out.tiles = tiles.size();
  out.tiled =
      store::compress(std::as_bytes(std::span<const std::uint64_t>(tiles)), kNodeCompressionLevel);
  return out;
}

void put_node(sqlite3* db, const std::string& name, const EncodedNode& node) {
  Statement insert(db,
                   "INSERT OR REPLACE INTO lod_nodes (code, leaf, points_below, points, "
                   "level_ends, bounds, max_radius, data) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
                   name);
  insert.bind_int(1, static_cast<std::int64_t>(node.key.code()))
      .bind_int(2, node.leaf ? 1 : 0)
      .bind_int(3, static_cast<std::int64_t>(node.points_below))
      .bind_int(4, static_cast<std::int64_t>(node.points))
      .bind_blob(5, bytes_of(node.level_ends.data(), node.level_ends.size()))
      .bind_blob(6, bytes_of(node.bounds.data(), node.bounds.size()))
      .bind_double(7, node.max_radius)
      .bind_blob(8, node.data)
      .run();
  Statement tiled(
      db, "INSERT OR REPLACE INTO lod_node_tiles (code, count, tiles) VALUES (?1, ?2, ?3)", name);
  tiled.bind_int(1, static_cast<std::int64_t>(node.key.code()))
      .bind_int(2, static_cast<std::int64_t>(node.tiles))
      .bind_blob(3, node.tiled)
      .run();
}

std::vector<std::uint8_t> compress_owners(std::span<const std::uint32_t> owners) {
  return store::compress(std::as_bytes(owners), kNodeCompressionLevel);
}

void put_compressed_owners(sqlite3* db, const std::string& name, std::uint16_t scan, int band,
                           std::span<const std::uint8_t> compressed) {
  Statement insert(
      db, "INSERT OR REPLACE INTO lod_pixels (point_scan, band, owners) VALUES (?1, ?2, ?3)", name);
  insert.bind_int(1, scan).bind_int(2, band).bind_blob(3, compressed).run();
}

void put_scan(sqlite3* db, const std::string& name, const LodScan& scan) {
  Statement insert(db,
                   "INSERT OR REPLACE INTO lod_scans (point_scan, scan_id, name, intensity_low, "
                   "intensity_high, pose, source, owners_source, digest_rows, columns, content) "
                   "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)",
                   name);
  insert.bind_int(1, scan.index)
      .bind_int(2, scan.scan_id)
      .bind_text(3, scan.name)
      .bind_double(4, scan.intensity_low)
      .bind_double(5, scan.intensity_high)
      .bind_blob(6, bytes_of(scan.T_world_scan.matrix().data(), 16))
      .bind_text(7, scan.source)
      .bind_text(8, scan.owners_source)
      .bind_int(9, scan.digest_rows)
      .bind_int(10, scan.columns)
      .bind_text(11, scan.content)
      .run();
}

}  // namespace schema

LodStoreWriter::LodStoreWriter(const std::filesystem::path& file, const LodHeader& header,
                               const std::vector<LodScan>& scans)
    : file_(file),
      partial_(file.string() + ".partial-" + std::to_string(::getpid())),
      header_(header),
      scans_(scans) {
  remove_stale_partials(file);
  db_ = schema::connect(partial_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  try {
    const std::string name = partial_.string();
    // The partial file is thrown away on any failure: no journal needed.
    // Pages of 64 KiB: a node's points (tens to hundreds of kilobytes) are
    // then read and written a few pages at a time, not page by page.
    store::sqlite::execute(
        db_, "PRAGMA page_size = 65536; PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF;",
        name);
    store::sqlite::execute(db_, schema::kSchema, name);
    store::sqlite::execute(
        db_, ("PRAGMA application_id = " + std::to_string(schema::kLodApplicationId)).c_str(),
        name);
    store::sqlite::execute(db_, "BEGIN", name);
    for (const LodScan& scan : scans) schema::put_scan(db_, name, scan);
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
  const schema::EncodedNode encoded = schema::encode_node(header_.cube, scans_, node);
  const std::lock_guard lock(mutex_);
  schema::put_node(db_, partial_.string(), encoded);
  points_ += node.points.size();
  ++nodes_;
}

void LodStoreWriter::put_owners(std::uint16_t scan, int band,
                                std::span<const std::uint32_t> owners) {
  assert(!committed_ && "put_owners before commit");
  const std::vector<std::uint8_t> compressed = schema::compress_owners(owners);
  const std::lock_guard lock(mutex_);
  schema::put_compressed_owners(db_, partial_.string(), scan, band, compressed);
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
  sync_folder(file_);
  committed_ = true;
}

}  // namespace scanbench::lod
