#include "modeling/lod/lod_store.hpp"

#include <algorithm>
#include <cstring>

#include "core/errors.hpp"
#include "modeling/lod/lod_schema.hpp"
#include "modeling/store/zstd_blob.hpp"

namespace scanbench::lod {
namespace {

using schema::damaged;
using schema::node_name;
using store::sqlite::Statement;

template <typename T>
bool read_blob(const Statement& statement, int column, T* out, std::size_t count) {
  const std::span<const std::uint8_t> blob = statement.column_blob(column);
  if (blob.size() != count * sizeof(T)) return false;
  if (count > 0) std::memcpy(out, blob.data(), blob.size());
  return true;
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
  if (s.column_int(0) >= 1 && s.column_int(0) < kLodFormatVersion) {
    damaged(file, "its header",
            "is of format " + std::to_string(s.column_int(0)) +
                ", older than this scanbench writes: run `scanbench lod` to rebuild it");
  }
  if (s.column_int(0) < 1 || s.column_int(8) < kCellBits || s.column_int(8) > 32 ||
      s.column_int(9) < 1 || s.column_int(10) < 0 || s.column_int(11) < 0) {
    damaged(file, "its header", "is damaged: run `scanbench lod` to rebuild the store");
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
  Statement s(db,
              "SELECT point_scan, scan_id, name, intensity_low, intensity_high, pose, source, "
              "owners_source, digest_rows, columns, content FROM lod_scans ORDER BY point_scan",
              file.string());
  std::vector<LodScan> scans;
  while (s.step()) {
    LodScan scan;
    scan.index = static_cast<std::uint16_t>(s.column_int(0));
    scan.scan_id = s.column_int(1);
    scan.name = s.column_text(2);
    scan.intensity_low = static_cast<float>(s.column_double(3));
    scan.intensity_high = static_cast<float>(s.column_double(4));
    scan.source = s.column_text(6);
    scan.owners_source = s.column_text(7);
    scan.digest_rows = static_cast<int>(std::clamp<std::int64_t>(s.column_int(8), 0, 1 << 30));
    scan.columns = static_cast<int>(std::clamp<std::int64_t>(s.column_int(9), 0, 1 << 30));
    scan.content = s.column_text(10);
    if (!read_blob(s, 5, scan.T_world_scan.matrix().data(), 16) || scan.digest_rows < 1 ||
        !scan.T_world_scan.matrix().allFinite() ||
        scan.index != static_cast<std::uint16_t>(scans.size())) {
      damaged(file, "scan " + std::to_string(scan.scan_id) + " (" + scan.name + ")",
              "has a damaged description: run `scanbench lod` to rebuild the store");
    }
    scans.push_back(std::move(scan));
  }
  return scans;
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
  // Read-write where it may, though it only reads: the first read then
  // rolls back what an update that crashed left in the journal.
  sqlite3* db = nullptr;
  try {
    db = schema::connect(file, SQLITE_OPEN_READWRITE);
  } catch (const core::RuntimeFailure&) {
    db = schema::connect(file, SQLITE_OPEN_READONLY);
  }
  LodStore store(file, db);
  const std::string name = file.string();
  const auto id = static_cast<std::uint32_t>(pragma_int(store.db_, "PRAGMA application_id", name));
  if (id != schema::kLodApplicationId) {
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
    const std::int64_t code = s.column_int(0);
    const int deepest = header_.cube.max_depth();
    if (code < 1 || static_cast<std::uint64_t>(code) >= (std::uint64_t{2} << (3 * deepest))) {
      damaged(file_, "node " + std::to_string(code), "has a damaged code: run `scanbench lod`");
    }
    node.key = NodeKey::from_code(static_cast<std::uint64_t>(code));
    node.leaf = s.column_int(1) != 0;
    node.points_below = static_cast<std::uint64_t>(s.column_int(2));
    node.points = static_cast<std::uint32_t>(s.column_int(3));
    std::array<float, 6> bounds{};
    const bool levels_rise = read_blob(s, 4, node.level_ends.data(), node.level_ends.size()) &&
                             std::is_sorted(node.level_ends.begin(), node.level_ends.end()) &&
                             node.level_ends.back() == node.points;
    if (!levels_rise || !read_blob(s, 5, bounds.data(), bounds.size()) ||
        node.points > node.points_below) {
      damaged(file_, node_name(node.key),
              "has a damaged description: run `scanbench lod` to rebuild the store");
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

LodStore::StoredPoints LodStore::read_stored_points(const NodeKey& node) const {
  Statement s(db_, "SELECT points, data FROM lod_nodes WHERE code = ?1", file_.string());
  s.bind_int(1, static_cast<std::int64_t>(node.code()));
  if (!s.step()) damaged(file_, node_name(node), "is missing");
  const std::span<const std::uint8_t> data = s.column_blob(1);
  return {node, static_cast<std::uint64_t>(std::max<std::int64_t>(0, s.column_int(0))),
          std::vector<std::uint8_t>(data.begin(), data.end())};
}

std::vector<LodPoint> LodStore::decode_points(const StoredPoints& stored) const {
  const NodeKey& node = stored.key;
  const store::BlobContext context{file_.string(), node_name(node)};
  // Checked before anything is allocated for it: a damaged count must not
  // ask for the machine's memory.
  store::check_blob_size(stored.data, stored.count * sizeof(LodPoint), context);
  std::vector<LodPoint> points(stored.count);
  store::decompress_into(stored.data, std::as_writable_bytes(std::span<LodPoint>(points)), context);
  // What the renderer will index with: within the node and the scans.
  const std::uint64_t edge = header_.cube.node_edge(node.depth);
  for (const LodPoint& p : points) {
    if (p.offset[0] >= edge || p.offset[1] >= edge || p.offset[2] >= edge ||
        p.scan >= scans_.size()) {
      damaged(file_, node_name(node), "holds a point outside it: run `scanbench lod`");
    }
  }
  return points;
}

std::vector<std::uint32_t> LodStore::owners(const LodScan& scan, int band,
                                            std::size_t pixels) const {
  Statement s(db_, "SELECT owners FROM lod_pixels WHERE point_scan = ?1 AND band = ?2",
              file_.string());
  s.bind_int(1, scan.index).bind_int(2, band);
  const std::string where = "scan " + std::to_string(scan.scan_id) + " (" + scan.name +
                            "), the owners of band " + std::to_string(band);
  if (!s.step()) damaged(file_, where, "are missing: run `scanbench lod --rebuild`");
  const store::BlobContext context{file_.string(), where};
  store::check_blob_size(s.column_blob(0), pixels * sizeof(std::uint32_t), context);
  std::vector<std::uint32_t> owners(pixels);
  store::decompress_into(s.column_blob(0), std::as_writable_bytes(std::span<std::uint32_t>(owners)),
                         context);
  return owners;
}

std::set<std::uint64_t> LodStore::nodes_in_tiles(const std::set<std::uint64_t>& tiles) const {
  std::set<std::uint64_t> codes;
  if (tiles.empty()) return codes;
  Statement s(db_, "SELECT code, count, tiles FROM lod_node_tiles", file_.string());
  std::vector<std::uint64_t> held;
  while (s.step()) {
    const auto code = static_cast<std::uint64_t>(s.column_int(0));
    const auto count = static_cast<std::uint64_t>(std::max<std::int64_t>(0, s.column_int(1)));
    const std::span<const std::uint8_t> blob = s.column_blob(2);
    const store::BlobContext context{file_.string(),
                                     node_name(NodeKey::from_code(code)) + ", its tiles"};
    store::check_blob_size(blob, count * sizeof(std::uint64_t), context);
    held.resize(count);
    store::decompress_into(blob, std::as_writable_bytes(std::span<std::uint64_t>(held)), context);
    for (const std::uint64_t tile : held) {
      if (tiles.count(tile)) {
        codes.insert(code);
        break;
      }
    }
  }
  return codes;
}

}  // namespace scanbench::lod
