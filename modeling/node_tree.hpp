// What the commands that change the object tree or its pixels share
// (internal to modeling/: selection, tree and register): the tree as a map
// they edit, the checks they make before they write, the membership layers,
// and the nodes' figures (point count, mean footprint, world bounding box)
// computed from the pixels of every scan.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "modeling/command_json.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::modeling {

using Tree = std::map<std::int64_t, store::ObjectNode>;

// What a node's cached figures sum up.
struct Figures {
  std::int64_t points = 0;
  std::int64_t with_footprint = 0;  // points of scans that have geometry
  double footprint_sum = 0.0;
  Eigen::AlignedBox3d box;  // starts empty

  void add(const Figures& other) {
    points += other.points;
    with_footprint += other.with_footprint;
    footprint_sum += other.footprint_sum;
    if (!other.box.isEmpty()) box.extend(other.box);
  }
};

// Throws core::InputError naming `where` ("node 4", "name") and no file:
// the CLI and the scripts add theirs.
[[noreturn]] void refuse(const std::string& where, const std::string& problem);

// The live nodes by id (Project::object_tree).
Tree load_tree(const store::Project& project);

// Node `id` of `tree`; refused when there is none.
const store::ObjectNode& require_node(const Tree& tree, std::int64_t id);

// Refuses a parent that is not a group of `tree` (none is the roots: fine).
void require_group(const Tree& tree, std::optional<std::int64_t> parent);

// Refuses a name that is only spaces, longer than store::kMaxNodeNameBytes,
// not UTF-8 or holding a control character.
void require_name(const std::string& name);

// True when `ancestor` is `node` or above it.
bool is_at_or_above(const Tree& tree, std::int64_t ancestor, std::int64_t node);

// Scan `scan_id`'s membership layer; all 0 (still to be segmented) when it
// has none.
std::vector<std::uint32_t> load_membership(const store::Project& project, std::int64_t scan_id,
                                           std::size_t pixels);

// Writes scan `scan_id`'s membership layer as part of `edit`.
void put_membership(store::Project& project, store::Project::Edit& edit, std::int64_t scan_id,
                    const std::vector<std::uint32_t>& membership);

// Every node's figures from the membership layers of all scans (`changed`
// holds the memberships this command writes, in place of the stored ones;
// `moved` the poses it writes), groups summing their descendants.
std::map<std::int64_t, Figures> compute_figures(
    const store::Project& project, const Tree& tree,
    const std::map<std::int64_t, std::vector<std::uint32_t>>& changed,
    const std::map<std::int64_t, Eigen::Isometry3d>& moved = {});

// The nodes of `tree` whose figures `figures` changes, with the new figures.
std::vector<store::ObjectNode> with_new_figures(const Tree& tree,
                                                const std::map<std::int64_t, Figures>& figures);

// Writes a new version of every node whose figures `figures` changes.
void refresh_figures(store::Project& project, store::Project::Edit& edit, const Tree& tree,
                     const std::map<std::int64_t, Figures>& figures);

// A parent in a command's settings: its id, or null for the roots.
nlohmann::json parent_json(std::optional<std::int64_t> parent);

// `count` node ids from the project's next free one; refused when they would
// reach kDeletedPoints, the largest a membership layer can name.
std::int64_t fresh_ids(const store::Project& project, std::size_t count);

// The membership layers of every scan in which a pixel of one of `owners`
// now goes to `replacement` (an object, the pool or kDeletedPoints), with
// those pixels rewritten; scans without such pixels are left out.
std::map<std::int64_t, std::vector<std::uint32_t>> reassign_pixels(
    const store::Project& project, const std::unordered_set<std::uint32_t>& owners,
    std::uint32_t replacement);

// The nodes whose figures change when the scans of `poses` move there (and
// the memberships of `changed` replace the stored ones), each with its new
// figures: what a command that moves scans (register) writes with put_node
// in its own Edit, so the tree's boxes follow the scans and undo with them.
std::vector<store::ObjectNode> node_figures_after_moving(
    const store::Project& project, const std::map<std::int64_t, Eigen::Isometry3d>& poses,
    const std::map<std::int64_t, std::vector<std::uint32_t>>& changed = {});

}  // namespace scanbench::modeling
