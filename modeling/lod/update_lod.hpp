// Updating a project's level-of-detail store in place (docs/lod.md, seed
// 002): after a commit, a delete, a separate, a merge of objects, a merge of
// scans, a new or moved scan, or an undo or redo of any of them, only the
// nodes holding the pixels that changed are written, in one SQLite
// transaction, so a crash leaves the old store or the new one.
//
// The store keeps a digest of every pixel of every scan (its point's
// object, kNotShown or kNotInModel) and the scan tiles of each node. An
// update reads again only the scans whose keep mask or membership was
// written by another command since, and of those only these two layers,
// and compares them with the digest. It reads the nodes of the changed
// tiles, relabelling their points as it reads them, and edits the octree
// (octree_edit.hpp): points shown now and not before are inserted (only
// they need their scan read whole), points shown before and not now are
// deleted. A moved scan's points are deleted and inserted again. The
// result is the store a build from scratch with the same cube gives, node
// for node.
//
// It cannot update (and says why) when a scan's points themselves changed
// (new geometry values, a new import), a scan went, a new or moved scan
// reaches outside the store's cube, or most of the model moved: then the
// store is built again.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "core/progress.hpp"
#include "modeling/lod/build_lod.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::lod {

struct LodUpdateResult {
  std::filesystem::path store;
  std::int64_t from_revision = 0, project_revision = 0;
  std::size_t scans_read = 0;   // scans whose pixels were compared with the digest
  std::size_t scans_added = 0;  // new scans, inserted
  std::uint64_t points_added = 0, points_removed = 0, points_relabelled = 0;
  std::uint64_t nodes_read = 0;     // nodes whose points the edit read
  std::uint64_t nodes_written = 0;  // nodes rewritten or new
  std::uint64_t nodes_removed = 0;
  // The codes of the nodes rewritten, new or removed: a renderer of the
  // store keeps what it holds of every other node.
  std::vector<std::uint64_t> rewritten;
  std::uint64_t points = 0, nodes = 0;  // in the store after
  double seconds = 0.0;
  // Of which: reading the changed scans; reading the nodes and editing the
  // octree; writing.
  double read_seconds = 0.0, edit_seconds = 0.0, write_seconds = 0.0;
};

// Brings the store (settings.output, or beside the project) up to the
// project's current state in place. None when it cannot, with the reason
// in `why_not`: the store is missing, unreadable or of another leaf size,
// or the project changed in a way only a build can follow (see above).
// Throws as build_lod when a scan is damaged; core::Cancelled through
// `progress`, leaving the store as it was.
std::optional<LodUpdateResult> update_lod(const store::Project& project,
                                          const LodBuildSettings& settings,
                                          core::Progress& progress, std::string& why_not);

// What refresh_lod did: one of the two (an update that changed nothing
// when the store was current).
struct LodRefreshResult {
  std::optional<LodUpdateResult> updated;
  std::optional<LodBuildResult> built;
  std::string why_built;  // why it could not update; empty when it did
  const std::filesystem::path& store() const { return updated ? updated->store : built->store; }
  double seconds() const { return updated ? updated->seconds : built->seconds; }
};

// The store brought to the project's state: left alone when current,
// updated in place when it can be, else built.
LodRefreshResult refresh_lod(const store::Project& project, const LodBuildSettings& settings,
                             core::Progress& progress);

}  // namespace scanbench::lod
