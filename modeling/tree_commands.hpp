// The object tree's commands (seed 004 §4.4): group, rename, hide, show,
// reparent, ungroup, merge and delete nodes; each one journaled command
// (store/project.hpp) that reads and computes first, then writes its node
// versions and membership layers in one Edit, so undo and redo restore the
// project exactly, across processes. A node's figures (point count, mean
// footprint, world bounding box) follow every change of its points.
//
// Pixels: a scan's "membership" layer (u32) names the object owning each
// pixel (0 = still to be segmented, store::kDeletedPoints = deleted).
//
// Errors: a node that does not exist, a node made its own ancestor, a name
// that is only spaces, longer than store::kMaxNodeNameBytes, not UTF-8 or
// holding a control character: core::InputError naming it, and nothing
// written.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "modeling/store/project.hpp"

namespace scanbench::modeling {

struct NodeCommandResult {
  std::int64_t command_id = 0;
  std::int64_t node_id = 0;  // the node made or changed
};

struct GroupSettings {
  std::string name;
  std::optional<std::int64_t> parent;  // none: a root
  std::vector<std::int64_t> children;  // existing nodes moved into the group
};

// A new group, holding `children`.
NodeCommandResult group_nodes(store::Project& project, const GroupSettings& settings);

struct NodeEdit {
  std::int64_t node = 0;
  std::optional<std::string> name;                    // rename
  std::optional<bool> hidden;                         // hide or show
  std::optional<std::optional<std::int64_t>> parent;  // reparent (inner none: to the roots)
  // More nodes hidden, shown or reparented with it, in the same command
  // (the proposals a review accepts); the name is the first node's only.
  std::vector<std::int64_t> others;
};

// Renames, hides or shows, or reparents a node and `others` (what `edit`
// holds), as one command.
NodeCommandResult edit_node(store::Project& project, const NodeEdit& edit);

struct UngroupResult {
  std::int64_t command_id = 0;
  std::vector<std::int64_t> children;  // moved to the group's parent, in id order
};

// Dissolves a group: its children move up to the group's parent (or become
// roots), keeping their points, and the group is removed.
UngroupResult ungroup_node(store::Project& project, std::int64_t group);

enum class DeletedPoints {
  kToPool,   // the points are to be segmented again
  kDeleted,  // the points are marked deleted
};

struct DeleteSettings {
  std::int64_t node = 0;
  DeletedPoints points = DeletedPoints::kToPool;
  std::vector<std::int64_t> others;  // deleted with it (the proposals a review rejects)
};

// Deletes a node (and `others`) with everything below it, as one command;
// their objects' points go back to the pool or are marked deleted.
NodeCommandResult delete_node(store::Project& project, const DeleteSettings& settings);

struct MergeSettings {
  std::vector<std::int64_t> objects;  // at least two; the first one takes the others' points
};

// Merges objects into the first: the others' pixels (in every scan) become
// its pixels and the others are removed (the inverse of separate, and how a
// user merges proposals).
NodeCommandResult merge_objects(store::Project& project, const MergeSettings& settings);

// Which scans each node's points come from, and how many: node id → scan
// id → points (a group's sum those below it; scans giving none are left
// out). Reads only the membership layers, one scan at a time.
using ScanCoverage = std::map<std::int64_t, std::map<std::int64_t, std::int64_t>>;
ScanCoverage scan_coverage(const store::Project& project);

}  // namespace scanbench::modeling
