#include "modeling/node_tree.hpp"

#include <algorithm>

#include "core/errors.hpp"
#include "core/text.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {

[[noreturn]] void refuse(const std::string& where, const std::string& problem) {
  core::FilePosition position;
  position.detail = where;
  throw core::InputError("", position, problem);
}

Tree load_tree(const store::Project& project) {
  return project.object_tree();
}

const store::ObjectNode& require_node(const Tree& tree, std::int64_t id) {
  const auto found = tree.find(id);
  if (found == tree.end()) refuse("node " + std::to_string(id), "no such node");
  return found->second;
}

void require_group(const Tree& tree, std::optional<std::int64_t> parent) {
  if (parent && require_node(tree, *parent).kind != store::NodeKind::kGroup) {
    refuse("node " + std::to_string(*parent), "is an object, not a group: it cannot hold nodes");
  }
}

void require_name(const std::string& name) {
  if (name.find_first_not_of(" \t\r\n") == std::string::npos)
    refuse("name", "a node needs a name (not only spaces)");
  if (name.size() > store::kMaxNodeNameBytes) {
    refuse("name", "is " + std::to_string(name.size()) +
                       " bytes long; a node's name holds at most " +
                       std::to_string(store::kMaxNodeNameBytes));
  }
  if (!core::is_valid_utf8(name)) refuse("name", "is not valid UTF-8");
  if (core::has_control_characters(name))
    refuse("name", "holds a control character (a newline, a tab, ESC, NUL …)");
}

// True when `ancestor` is `node` or above it.
bool is_at_or_above(const Tree& tree, std::int64_t ancestor, std::int64_t node) {
  for (std::optional<std::int64_t> at = node; at;) {
    if (*at == ancestor) return true;
    const auto found = tree.find(*at);
    at = found == tree.end() ? std::nullopt : found->second.parent;
  }
  return false;
}

std::vector<std::uint32_t> load_membership(const store::Project& project, std::int64_t scan_id,
                                           std::size_t pixels) {
  auto stored = project.load_layer<std::uint32_t>(scan_id, store::layer::kMembership,
                                                  store::ElementType::kU32);
  return stored ? std::move(*stored) : std::vector<std::uint32_t>(pixels, 0);
}

void put_membership(store::Project& project, store::Project::Edit& edit, std::int64_t scan_id,
                    const std::vector<std::uint32_t>& membership) {
  project.put_layer(edit, scan_id,
                    store::encode_layer<std::uint32_t>(store::layer::kMembership,
                                                       store::ElementType::kU32, membership));
}

// Every node's figures from the membership layers of all scans (`changed`
// holds the memberships this command writes, in place of the stored ones;
// `moved` the poses it writes), groups summing their descendants.
std::map<std::int64_t, Figures> compute_figures(
    const store::Project& project, const Tree& tree,
    const std::map<std::int64_t, std::vector<std::uint32_t>>& changed,
    const std::map<std::int64_t, Eigen::Isometry3d>& moved) {
  std::map<std::int64_t, Figures> own;
  for (const store::StoredScanSummary& stored : project.scans()) {
    const auto replaced = changed.find(stored.id);
    const std::vector<std::string> names = project.layer_names(stored.id);
    const bool has_layer =
        replaced != changed.end() ||
        std::find(names.begin(), names.end(), store::layer::kMembership) != names.end();
    if (!has_layer) continue;
    acquisition::Scan scan = project.load_scan(stored.id);
    if (const auto pose = moved.find(stored.id); pose != moved.end())
      scan.T_world_scan = pose->second;
    const std::optional<acquisition::ScanGeometry> geometry =
        store::load_geometry(project, stored.id);
    const std::vector<std::uint32_t> membership =
        replaced != changed.end() ? replaced->second
                                  : load_membership(project, stored.id, scan.pixel_count());
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.columns; ++col) {
        const std::uint32_t owner = membership[scan.index(row, col)];
        if (owner == 0 || owner == store::kDeletedPoints) continue;
        Figures& f = own[owner];
        ++f.points;
        if (geometry) {
          f.footprint_sum += geometry->footprint_m[scan.index(row, col)];
          ++f.with_footprint;
        }
        f.box.extend(acquisition::point_in_world(scan, row, col));
      }
    }
  }
  std::map<std::int64_t, Figures> total;
  for (const auto& [id, figures] : own) {
    for (std::optional<std::int64_t> at = id; at && tree.count(*at); at = tree.at(*at).parent) {
      total[*at].add(figures);
    }
  }
  return total;
}

// The nodes of `tree` whose figures `figures` changes, with the new figures.
std::vector<store::ObjectNode> with_new_figures(const Tree& tree,
                                                const std::map<std::int64_t, Figures>& figures) {
  std::vector<store::ObjectNode> changed;
  for (const auto& [id, node] : tree) {
    const auto found = figures.find(id);
    const Figures f = found == figures.end() ? Figures{} : found->second;
    const std::optional<double> mean_footprint_m =
        f.with_footprint > 0
            ? std::optional<double>(f.footprint_sum / static_cast<double>(f.with_footprint))
            : std::nullopt;
    const std::optional<Eigen::AlignedBox3d> bbox_world =
        f.box.isEmpty() ? std::nullopt : std::optional<Eigen::AlignedBox3d>(f.box);
    const bool same = f.points == node.points && mean_footprint_m == node.mean_footprint_m &&
                      bbox_world.has_value() == node.bbox_world.has_value() &&
                      (!bbox_world || (bbox_world->min() == node.bbox_world->min() &&
                                       bbox_world->max() == node.bbox_world->max()));
    if (same) continue;
    store::ObjectNode& updated = changed.emplace_back(node);
    updated.points = f.points;
    updated.mean_footprint_m = mean_footprint_m;
    updated.bbox_world = bbox_world;
  }
  return changed;
}

// Writes a new version of every node whose figures `figures` changes.
void refresh_figures(store::Project& project, store::Project::Edit& edit, const Tree& tree,
                     const std::map<std::int64_t, Figures>& figures) {
  for (const store::ObjectNode& node : with_new_figures(tree, figures))
    project.put_node(edit, node);
}

nlohmann::json parent_json(std::optional<std::int64_t> parent) {
  return parent ? nlohmann::json(*parent) : nlohmann::json(nullptr);
}

// `count` node ids from the project's next free one; refused when they would
// reach kDeletedPoints, the largest a membership layer can name.
std::int64_t fresh_ids(const store::Project& project, std::size_t count) {
  const std::int64_t first = project.new_node_id();
  if (first + static_cast<std::int64_t>(count) > static_cast<std::int64_t>(store::kDeletedPoints)) {
    refuse("object tree", "the project has used every node id a membership layer can hold");
  }
  return first;
}

// The membership layers of every scan in which a pixel of one of `owners`
// now goes to `replacement` (an object, the pool or kDeletedPoints), with
// those pixels rewritten; scans without such pixels are left out.
std::map<std::int64_t, std::vector<std::uint32_t>> reassign_pixels(
    const store::Project& project, const std::unordered_set<std::uint32_t>& owners,
    std::uint32_t replacement) {
  std::map<std::int64_t, std::vector<std::uint32_t>> changed;
  for (const store::StoredScanSummary& stored : project.scans()) {
    auto membership = project.load_layer<std::uint32_t>(stored.id, store::layer::kMembership,
                                                        store::ElementType::kU32);
    if (!membership) continue;
    bool touched = false;
    for (std::uint32_t& owner : *membership) {
      if (owner == 0 || owner == store::kDeletedPoints || !owners.count(owner)) continue;
      owner = replacement;
      touched = true;
    }
    if (touched) changed.emplace(stored.id, std::move(*membership));
  }
  return changed;
}

std::vector<store::ObjectNode> node_figures_after_moving(
    const store::Project& project, const std::map<std::int64_t, Eigen::Isometry3d>& poses,
    const std::map<std::int64_t, std::vector<std::uint32_t>>& changed) {
  const Tree tree = load_tree(project);
  if (tree.empty()) return {};
  return with_new_figures(tree, compute_figures(project, tree, changed, poses));
}

}  // namespace scanbench::modeling
