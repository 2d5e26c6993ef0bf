// The level-of-detail store (docs/lod.md): the nodes of a project's octree
// (octree_sampling.hpp) in an SQLite file beside the project,
// PROJECT.sbproj.lod. A cache derived from the project: rebuildable at any
// time, never needed to open the project, and tied to the project revision
// it reflects. A build writes PROJECT.sbproj.lod.partial-PID and renames it
// over the store when complete and synced, so a crash leaves the old store
// or the new one; two builds at once each write their own.
//
// One LodStore is one connection, for one thread at a time: a loader thread
// opens its own.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "modeling/lod/lod_point.hpp"
#include "modeling/lod/octree_cube.hpp"
#include "modeling/lod/octree_sampling.hpp"

struct sqlite3;

namespace scanbench::lod {

// 2: the owners of every pixel (the digest edits compare with) and what
// each scan's points were read from.
inline constexpr int kLodFormatVersion = 2;

// A pixel's owner in the store's digest (LodStore::owners) is the object
// of its point when the store holds it (0: none), else one of these:
inline constexpr std::uint32_t kNotInModel = 0xffffffffu;  // no point: no return, or mixed
inline constexpr std::uint32_t kNotShown = 0xfffffffeu;    // merged away or deleted
// Whether the store holds the point of a pixel whose owner is `owner`.
inline bool in_store(std::uint32_t owner) {
  return owner < kNotShown;
}

struct LodHeader {
  std::int64_t project_revision = 0;  // the project's revision the store reflects
  // World = origin + metres from it; the cube counts quanta from it.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  OctreeCube cube;
  OctreeSettings octree;
  std::uint64_t points = 0;
  std::uint64_t nodes = 0;
};

// A scan the store holds points of.
struct LodScan {
  std::uint16_t index = 0;  // LodPoint::scan
  std::int64_t scan_id = 0;
  std::string name;
  // The spread of its intensities (2nd–98th percentile of its in-model
  // points) that LodPoint::intensity maps to 0…255.
  float intensity_low = 0.0f;
  float intensity_high = 1.0f;
  Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();  // the pose its points have
  // The commands whose layers its points were read from (scan_sources):
  // the layers that place and describe a point, and those that say whether
  // it is shown and whose it is.
  std::string source{}, owners_source{};
  // The rows of a band of its pixel digest (LodStore::owners).
  int digest_rows = 1;
  int columns = 0;        // of its grid (0: unknown, a store written from points in memory)
  std::string content{};  // the values of the layers `source` names (scan_points_content)
};

// Which tile of its scan's grid (64 × 64 pixels) the point of `pixel`
// lies in, with the store's index of its scan: what the store records of
// each node, so that an update finds the nodes holding changed pixels.
inline std::uint64_t tile_of(const LodScan& scan, std::uint32_t pixel) {
  constexpr int kTileBits = 6;
  const auto columns = static_cast<std::uint32_t>(std::max(scan.columns, 1));
  const std::uint32_t across = (columns + (1u << kTileBits) - 1) >> kTileBits;
  const std::uint32_t tile =
      (pixel / columns >> kTileBits) * across + (pixel % columns >> kTileBits);
  return (std::uint64_t{scan.index} << 32) | tile;
}

// A node without its points.
struct LodNodeInfo {
  NodeKey key;
  bool leaf = false;
  std::uint64_t points_below = 0;  // in its region: its own and its descendants'
  std::uint32_t points = 0;        // its own
  std::array<std::uint32_t, kNodeLevels> level_ends{};
  Eigen::AlignedBox3f bounds;  // of its points [m from the origin]; empty when it has none
  float max_radius_m = 0.0f;   // its largest splat radius
};

class LodStore {
 public:
  // PROJECT.lod beside the project file.
  static std::filesystem::path path_for(const std::filesystem::path& project);

  // Opens a store for reading. Throws core::InputError naming the file when
  // it is missing, not a store, of a newer format, or damaged;
  // core::RuntimeFailure when it cannot be read.
  static LodStore open(const std::filesystem::path& file);

  LodStore(LodStore&&) noexcept;
  LodStore& operator=(LodStore&&) noexcept;
  ~LodStore();

  const std::filesystem::path& path() const { return file_; }
  const LodHeader& header() const { return header_; }
  const std::vector<LodScan>& scans() const { return scans_; }

  // Every node, in the order of their locational codes (a node before its
  // descendants); none for a model without shown points. Throws
  // core::InputError naming the node when a node's description is damaged.
  std::vector<LodNodeInfo> nodes() const;

  // The points of `node`, in level order (offsets from its corner). Throws
  // core::InputError naming the node when its data is missing or damaged.
  std::vector<LodPoint> read_points(const NodeKey& node) const {
    return decode_points(read_stored_points(node));
  }

  // read_points in two steps: the node's row read (a connection serves
  // one thread), then its points decoded, on any thread.
  struct StoredPoints {
    NodeKey key;
    std::uint64_t count = 0;
    std::vector<std::uint8_t> data;  // compressed
  };
  StoredPoints read_stored_points(const NodeKey& node) const;
  std::vector<LodPoint> decode_points(const StoredPoints& stored) const;

  // The owner of every pixel of band `band` of scan `scan` (rows
  // [band · digest_rows, …)): the object of its point, kNotShown or
  // kNotInModel.
  // Throws core::InputError naming the scan and band when it is missing or
  // damaged.
  std::vector<std::uint32_t> owners(const LodScan& scan, int band, std::size_t pixels) const;

  // The nodes holding points of any of `tiles` (tile_of), by code.
  std::set<std::uint64_t> nodes_in_tiles(const std::set<std::uint64_t>& tiles) const;

 private:
  LodStore(std::filesystem::path file, sqlite3* db);
  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
  LodHeader header_;
  std::vector<LodScan> scans_;
};

// Writes a new store: into FILE.partial-PID, renamed over FILE by
// commit(). Destroyed without commit() (an error, a cancel), it removes the
// partial file and leaves the store at FILE as it was. Partial files of
// builds whose process is gone are removed when a build starts.
class LodStoreWriter {
 public:
  // Throws core::RuntimeFailure when the file cannot be made.
  LodStoreWriter(const std::filesystem::path& file, const LodHeader& header,
                 const std::vector<LodScan>& scans);
  ~LodStoreWriter();
  LodStoreWriter(const LodStoreWriter&) = delete;
  LodStoreWriter& operator=(const LodStoreWriter&) = delete;

  // Stores a finished node, once. Safe from several threads: each
  // compresses its node on its own, and they take turns to store.
  void put(const BuiltNode& node);

  // Stores the owners of band `band` of scan `scan` (LodStore::owners).
  // Safe from several threads.
  void put_owners(std::uint16_t scan, int band, std::span<const std::uint32_t> owners);

  // The points and nodes put so far.
  std::uint64_t points() const { return points_; }
  std::uint64_t nodes() const { return nodes_; }

  // Records the totals, makes the file durable and renames it over FILE.
  void commit();

 private:
  std::filesystem::path file_, partial_;
  sqlite3* db_ = nullptr;
  LodHeader header_;
  std::vector<LodScan> scans_;
  std::mutex mutex_;  // over db_ and the counts while building
  std::uint64_t points_ = 0, nodes_ = 0;
  bool committed_ = false;
};

}  // namespace scanbench::lod
