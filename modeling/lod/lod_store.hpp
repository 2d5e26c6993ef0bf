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
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "modeling/lod/lod_point.hpp"
#include "modeling/lod/octree_cube.hpp"
#include "modeling/lod/octree_sampling.hpp"

struct sqlite3;

namespace scanbench::lod {

inline constexpr int kLodFormatVersion = 1;

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
};

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
  std::vector<LodPoint> read_points(const NodeKey& node) const;

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

  // The points and nodes put so far.
  std::uint64_t points() const { return points_; }
  std::uint64_t nodes() const { return nodes_; }

  // Records the totals, makes the file durable and renames it over FILE.
  void commit();

 private:
  std::filesystem::path file_, partial_;
  sqlite3* db_ = nullptr;
  LodHeader header_;
  std::mutex mutex_;  // over db_ and the counts while building
  std::uint64_t points_ = 0, nodes_ = 0;
  bool committed_ = false;
};

}  // namespace scanbench::lod
