// The segmentation's commands (issue 13, seed 004 §4.1): a region grown
// into a scan's selection, the selection committed as an object of the
// tree, and the tree's edits. Each is one journaled command (project.hpp):
// it reads and computes first, then writes its layers and node versions in
// one Edit, so undo and redo restore the project exactly, across processes.
//
// Pixels: a scan's "selection" layer (u8) is the region being grown; its
// "membership" layer (u32) names the object owning each pixel (0 = still to
// be segmented, kDeletedPoints = deleted). Regions grow only through pixels
// still to be segmented.
//
// Errors: a scan or node that does not exist, a seed outside the grid, a
// scan without geometry, an empty selection, a node made its own ancestor,
// a name that is only spaces, longer than kMaxNodeNameBytes, not UTF-8 or
// holding a control character: core::InputError naming it, and nothing
// written.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/range_noise.hpp"
#include "modeling/project.hpp"
#include "segmentation/constraints.hpp"
#include "segmentation/proposals.hpp"
#include "segmentation/region_grow.hpp"

namespace scanbench::modeling {

enum class SelectMode {
  kReplace,   // the region becomes the selection
  kAdd,       // the region joins the selection
  kSubtract,  // the region leaves the selection
};

struct SelectSettings {
  std::int64_t scan_id = 0;
  int seed_row = 0;
  int seed_col = 0;
  SelectMode mode = SelectMode::kReplace;
  segmentation::GrowSettings grow;
  segmentation::Constraints constraints;  // image coordinates (constraints.hpp)
  acquisition::RangeNoise range_noise;    // the scanner's
};

struct SelectResult {
  std::int64_t command_id = 0;
  std::size_t region_pixels = 0;    // grown from the seed
  std::size_t selected_pixels = 0;  // in the selection afterwards
  bool seed_open = false;           // the seed could grow (usable, open, still to be segmented)
};

// Grows a region from the seed and combines it with the scan's selection.
SelectResult select_region(Project& project, const SelectSettings& settings);

struct CommitSettings {
  std::int64_t scan_id = 0;
  std::string name;                    // the new object's
  std::optional<std::int64_t> parent;  // a group; none: a root
};

struct NodeCommandResult {
  std::int64_t command_id = 0;
  std::int64_t node_id = 0;  // the node made or changed
};

// Makes the scan's selection a new object: its pixels leave the pool still
// to be segmented, the selection is emptied, and the object and its
// ancestors get their point count, mean footprint and world bounding box.
NodeCommandResult commit_selection(Project& project, const CommitSettings& settings);

struct GroupSettings {
  std::string name;
  std::optional<std::int64_t> parent;  // none: a root
  std::vector<std::int64_t> children;  // existing nodes moved into the group
};

// A new group, holding `children`.
NodeCommandResult group_nodes(Project& project, const GroupSettings& settings);

struct NodeEdit {
  std::int64_t node = 0;
  std::optional<std::string> name;                    // rename
  std::optional<bool> hidden;                         // hide or show
  std::optional<std::optional<std::int64_t>> parent;  // reparent (inner none: to the roots)
};

// Renames, hides or shows, or reparents a node (what `edit` holds).
NodeCommandResult edit_node(Project& project, const NodeEdit& edit);

struct UngroupResult {
  std::int64_t command_id = 0;
  std::vector<std::int64_t> children;  // moved to the group's parent, in id order
};

// Dissolves a group: its children move up to the group's parent (or become
// roots), keeping their points, and the group is removed.
UngroupResult ungroup_node(Project& project, std::int64_t group);

enum class DeletedPoints {
  kToPool,   // the points are to be segmented again
  kDeleted,  // the points are marked deleted
};

struct DeleteSettings {
  std::int64_t node = 0;
  DeletedPoints points = DeletedPoints::kToPool;
};

// Deletes a node with everything below it; its objects' points go back to
// the pool or are marked deleted.
NodeCommandResult delete_node(Project& project, const DeleteSettings& settings);

struct MergeSettings {
  std::vector<std::int64_t> objects;  // at least two; the first one takes the others' points
};

// Merges objects into the first: the others' pixels (in every scan) become
// its pixels and the others are removed (the inverse of separate, and how a
// user merges proposals).
NodeCommandResult merge_objects(Project& project, const MergeSettings& settings);

struct SeparateSettings {
  std::int64_t node = 0;     // an object
  std::int64_t scan_id = 0;  // the scan whose pixels are split
};

struct SeparateResult {
  std::int64_t command_id = 0;
  std::vector<std::int64_t> nodes;  // the object (its largest part) first, then the new ones
};

// Splits an object's pixels in one scan into their 8-connected parts: the
// largest stays the object, each other part becomes a new object beside it
// ("NAME 2", "NAME 3", …), with all its figures.
SeparateResult separate_object(Project& project, const SeparateSettings& settings);

struct ProposeSettings {
  std::int64_t scan_id = 0;
  std::string group_name = "proposals";  // the group that receives them
  std::optional<std::int64_t> parent;    // of that group; none: a root
  segmentation::ProposalSettings proposals;
  acquisition::RangeNoise range_noise;
};

// Automatic proposals (segmentation/proposals.hpp) on the scan's pixels still
// to be segmented, each committed as an object "proposal K" in a new group,
// for the user to accept (rename, reparent), merge (merge_objects) or reject
// (delete back to the pool). One command: undo takes them all back.
SeparateResult propose_objects(Project& project, const ProposeSettings& settings);

// The nodes whose figures (point count, mean footprint, world bounding box)
// change when the scans of `poses` move there, each with its new figures:
// what a command that moves scans (the register stage) writes with put_node
// in its own Edit, so the tree's boxes follow the scans and undo with them.
std::vector<ObjectNode> node_figures_after_moving(
    const Project& project, const std::map<std::int64_t, Eigen::Isometry3d>& poses);

}  // namespace scanbench::modeling
