#include "modeling/segment_commands.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <unordered_set>

#include "core/errors.hpp"
#include "core/text.hpp"
#include "modeling/scan_layers.hpp"
#include "segmentation/pixel_set.hpp"

namespace scanbench::modeling {

namespace {

using Tree = std::map<std::int64_t, ObjectNode>;

[[noreturn]] void refuse(const std::string& where, const std::string& problem) {
  core::FilePosition position;
  position.detail = where;
  throw core::InputError("", position, problem);
}

std::string dump(const nlohmann::json& json) {
  return json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

Tree load_tree(const Project& project) {
  return project.object_tree();
}

const ObjectNode& require_node(const Tree& tree, std::int64_t id) {
  const auto found = tree.find(id);
  if (found == tree.end()) refuse("node " + std::to_string(id), "no such node");
  return found->second;
}

void require_group(const Tree& tree, std::optional<std::int64_t> parent) {
  if (parent && require_node(tree, *parent).kind != NodeKind::kGroup) {
    refuse("node " + std::to_string(*parent), "is an object, not a group: it cannot hold nodes");
  }
}

void require_name(const std::string& name) {
  if (name.find_first_not_of(" \t\r\n") == std::string::npos)
    refuse("name", "a node needs a name (not only spaces)");
  if (name.size() > kMaxNodeNameBytes) {
    refuse("name", "is " + std::to_string(name.size()) +
                       " bytes long; a node's name holds at most " +
                       std::to_string(kMaxNodeNameBytes));
  }
  if (!core::is_valid_utf8(name)) refuse("name", "is not valid UTF-8");
  if (core::has_control_characters(name))
    refuse("name", "holds a control character (a newline, a tab, ESC, NUL …)");
}

// "`base` N", `base` cut (between UTF-8 characters) so that the name fits
// kMaxNodeNameBytes.
std::string numbered_name(const std::string& base, std::size_t number) {
  const std::string digits = std::to_string(number);
  std::size_t keep = std::min(base.size(), kMaxNodeNameBytes - 1 - digits.size());
  while (keep > 0 && keep < base.size() && (static_cast<unsigned char>(base[keep]) & 0xC0) == 0x80)
    --keep;
  // Appended apart: GCC 12 warns falsely on chains of std::string operator+ at -O3.
  std::string name(base, 0, keep);
  name += ' ';
  name += digits;
  return name;
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

std::vector<std::uint32_t> load_membership(const Project& project, std::int64_t scan_id,
                                           std::size_t pixels) {
  auto stored = project.load_layer<std::uint32_t>(scan_id, layer::kMembership, ElementType::kU32);
  return stored ? std::move(*stored) : std::vector<std::uint32_t>(pixels, 0);
}

segmentation::PixelSet load_selection(const Project& project, std::int64_t scan_id) {
  const auto stored =
      project.load_layer<std::uint8_t>(scan_id, layer::kSelection, ElementType::kU8);
  return stored ? segmentation::from_mask(*stored) : segmentation::PixelSet{};
}

void put_selection(Project& project, Project::Edit& edit, std::int64_t scan_id,
                   const segmentation::GridShape& shape, const segmentation::PixelSet& selection) {
  if (selection.empty()) {
    project.remove_layer(edit, scan_id, layer::kSelection);
    return;
  }
  const std::vector<std::uint8_t> mask = segmentation::to_mask(shape, selection);
  project.put_layer(edit, scan_id,
                    encode_layer<std::uint8_t>(layer::kSelection, ElementType::kU8, mask));
}

void put_membership(Project& project, Project::Edit& edit, std::int64_t scan_id,
                    const std::vector<std::uint32_t>& membership) {
  project.put_layer(edit, scan_id,
                    encode_layer<std::uint32_t>(layer::kMembership, ElementType::kU32, membership));
}

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

// Every node's figures from the membership layers of all scans (`changed`
// holds the memberships this command writes, in place of the stored ones;
// `moved` the poses it writes), groups summing their descendants.
std::map<std::int64_t, Figures> compute_figures(
    const Project& project, const Tree& tree,
    const std::map<std::int64_t, std::vector<std::uint32_t>>& changed,
    const std::map<std::int64_t, Eigen::Isometry3d>& moved = {}) {
  std::map<std::int64_t, Figures> own;
  for (const StoredScanSummary& stored : project.scans()) {
    const auto replaced = changed.find(stored.id);
    const std::vector<std::string> names = project.layer_names(stored.id);
    const bool has_layer = replaced != changed.end() ||
                           std::find(names.begin(), names.end(), layer::kMembership) != names.end();
    if (!has_layer) continue;
    acquisition::Scan scan = project.load_scan(stored.id);
    if (const auto pose = moved.find(stored.id); pose != moved.end())
      scan.T_world_scan = pose->second;
    const std::optional<acquisition::ScanGeometry> geometry = load_geometry(project, stored.id);
    const std::vector<std::uint32_t> membership =
        replaced != changed.end() ? replaced->second
                                  : load_membership(project, stored.id, scan.pixel_count());
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.columns; ++col) {
        const std::uint32_t owner = membership[scan.index(row, col)];
        if (owner == 0 || owner == kDeletedPoints) continue;
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
std::vector<ObjectNode> with_new_figures(const Tree& tree,
                                         const std::map<std::int64_t, Figures>& figures) {
  std::vector<ObjectNode> changed;
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
    ObjectNode& updated = changed.emplace_back(node);
    updated.points = f.points;
    updated.mean_footprint_m = mean_footprint_m;
    updated.bbox_world = bbox_world;
  }
  return changed;
}

// Writes a new version of every node whose figures `figures` changes.
void refresh_figures(Project& project, Project::Edit& edit, const Tree& tree,
                     const std::map<std::int64_t, Figures>& figures) {
  for (const ObjectNode& node : with_new_figures(tree, figures)) project.put_node(edit, node);
}

nlohmann::json polyline_json(const segmentation::Polyline& line) {
  nlohmann::json out = nlohmann::json::array();
  for (const Eigen::Vector2d& v : line) out.push_back({v.x(), v.y()});
  return out;
}

nlohmann::json select_json(const SelectSettings& s) {
  nlohmann::json barriers = nlohmann::json::array();
  for (const segmentation::Polyline& line : s.constraints.barriers)
    barriers.push_back(polyline_json(line));
  constexpr const char* kModes[] = {"replace", "add", "subtract"};
  return {{"scan", s.scan_id},
          {"seed", {s.seed_row, s.seed_col}},
          {"mode", kModes[static_cast<int>(s.mode)]},
          {"channel", segmentation::channel_name(s.grow.channel)},
          {"tolerance", s.grow.tolerance},
          {"mean_factor", s.grow.mean_factor},
          {"plane_footprints", s.grow.plane_footprints},
          {"continuity_footprints", s.grow.continuity_footprints},
          {"max_pixels", s.grow.max_pixels},
          {"lasso", polyline_json(s.constraints.lasso)},
          {"barriers", barriers},
          {"range_noise",
           {{"noise_m", s.range_noise.noise_m}, {"noise_per_m", s.range_noise.noise_per_m}}}};
}

nlohmann::json parent_json(std::optional<std::int64_t> parent) {
  return parent ? nlohmann::json(*parent) : nlohmann::json(nullptr);
}

// `count` node ids from the project's next free one; refused when they would
// reach kDeletedPoints, the largest a membership layer can name.
std::int64_t fresh_ids(const Project& project, std::size_t count) {
  const std::int64_t first = project.new_node_id();
  if (first + static_cast<std::int64_t>(count) > static_cast<std::int64_t>(kDeletedPoints)) {
    refuse("object tree", "the project has used every node id a membership layer can hold");
  }
  return first;
}

StoredScanSummary require_scan(const Project& project, std::int64_t scan_id) {
  for (const StoredScanSummary& stored : project.scans()) {
    if (stored.id == scan_id) return stored;
  }
  refuse("scan " + std::to_string(scan_id), "no such scan");
}

// The membership layers of every scan in which a pixel of one of `owners`
// now goes to `replacement` (an object, the pool or kDeletedPoints), with
// those pixels rewritten; scans without such pixels are left out.
std::map<std::int64_t, std::vector<std::uint32_t>> reassign_pixels(
    const Project& project, const std::unordered_set<std::uint32_t>& owners,
    std::uint32_t replacement) {
  std::map<std::int64_t, std::vector<std::uint32_t>> changed;
  for (const StoredScanSummary& stored : project.scans()) {
    auto membership =
        project.load_layer<std::uint32_t>(stored.id, layer::kMembership, ElementType::kU32);
    if (!membership) continue;
    bool touched = false;
    for (std::uint32_t& owner : *membership) {
      if (owner == 0 || owner == kDeletedPoints || !owners.count(owner)) continue;
      owner = replacement;
      touched = true;
    }
    if (touched) changed.emplace(stored.id, std::move(*membership));
  }
  return changed;
}

// 1 where an object owns the pixel or it is deleted: closed to growing.
std::vector<std::uint8_t> taken_mask(const std::vector<std::uint32_t>& membership) {
  std::vector<std::uint8_t> taken(membership.size());
  for (std::size_t i = 0; i < taken.size(); ++i) taken[i] = membership[i] != 0;
  return taken;
}

// The scan, its geometry (refused when missing) and the grid a region grows on.
struct Prepared {
  acquisition::Scan scan;
  acquisition::ScanGeometry geometry;
  segmentation::SegmentationGrid grid;
};

Prepared prepare(const Project& project, std::int64_t scan_id,
                 const acquisition::RangeNoise& noise) {
  Prepared p;
  p.scan = project.load_scan(scan_id);
  std::optional<acquisition::ScanGeometry> geometry = load_geometry(project, scan_id);
  if (!geometry) {
    refuse("scan " + std::to_string(scan_id), "has no geometry: run `scanbench geometry` first");
  }
  p.geometry = std::move(*geometry);
  segmentation::GridSettings settings;
  settings.range_noise = noise;
  p.grid = segmentation::prepare_grid(p.scan, p.geometry, settings);
  return p;
}

}  // namespace

SeparateResult separate_object(Project& project, const SeparateSettings& settings) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  const ObjectNode object = require_node(tree, settings.node);
  if (object.kind != NodeKind::kObject) {
    refuse("node " + std::to_string(settings.node), "is a group: only objects own pixels");
  }
  const acquisition::Scan scan = project.load_scan(settings.scan_id);
  std::vector<std::uint32_t> membership =
      load_membership(project, settings.scan_id, scan.pixel_count());
  segmentation::PixelSet owned;
  for (std::size_t i = 0; i < membership.size(); ++i) {
    if (membership[i] == static_cast<std::uint32_t>(object.id))
      owned.push_back(static_cast<std::uint32_t>(i));
  }
  const std::vector<segmentation::PixelSet> parts =
      segmentation::separate(segmentation::grid_shape(scan), owned);
  SeparateResult result;
  result.nodes.push_back(object.id);
  std::vector<ObjectNode> made;
  std::int64_t next = fresh_ids(project, parts.empty() ? 0 : parts.size() - 1);
  for (std::size_t k = 1; k < parts.size(); ++k) {
    ObjectNode part = object;
    part.id = next++;
    part.name = numbered_name(object.name, k + 1);
    for (const std::uint32_t p : parts[k]) membership[p] = static_cast<std::uint32_t>(part.id);
    tree.emplace(part.id, part);
    made.push_back(part);
    result.nodes.push_back(part.id);
  }
  const auto figures = compute_figures(project, tree, {{settings.scan_id, membership}});
  Project::Edit edit = project.begin_command(
      "separate", dump({{"node", settings.node}, {"scan", settings.scan_id}}), revision);
  for (const ObjectNode& part : made) project.put_node(edit, part);
  if (!made.empty()) put_membership(project, edit, settings.scan_id, membership);
  refresh_figures(project, edit, tree, figures);
  result.command_id = edit.command_id();
  edit.commit(dump({{"nodes", result.nodes}}));
  return result;
}

SeparateResult propose_objects(Project& project, const ProposeSettings& settings) {
  const std::int64_t revision = project.revision();
  require_name(settings.group_name);
  Tree tree = load_tree(project);
  require_group(tree, settings.parent);
  const Prepared p = prepare(project, settings.scan_id, settings.range_noise);
  std::vector<std::uint32_t> membership =
      load_membership(project, settings.scan_id, p.scan.pixel_count());
  const std::vector<std::uint8_t> open =
      segmentation::open_pixels(p.grid, {}, taken_mask(membership));
  const segmentation::ProposalResult proposed =
      segmentation::propose_regions(p.grid, open, p.geometry.confidence, settings.proposals);
  ObjectNode group;
  group.id = fresh_ids(project, 1 + proposed.regions.size());
  group.name = settings.group_name;
  group.kind = NodeKind::kGroup;
  group.parent = settings.parent;
  tree.emplace(group.id, group);
  SeparateResult result;
  std::vector<ObjectNode> made;
  for (std::size_t k = 0; k < proposed.regions.size(); ++k) {
    ObjectNode object;
    object.id = group.id + 1 + static_cast<std::int64_t>(k);
    object.name = "proposal " + std::to_string(k + 1);
    object.parent = group.id;
    for (const std::uint32_t px : proposed.regions[k])
      membership[px] = static_cast<std::uint32_t>(object.id);
    tree.emplace(object.id, object);
    made.push_back(object);
    result.nodes.push_back(object.id);
  }
  const auto figures = compute_figures(project, tree, {{settings.scan_id, membership}});
  Project::Edit edit = project.begin_command(
      "propose",
      dump({{"scan", settings.scan_id},
            {"group", settings.group_name},
            {"parent", parent_json(settings.parent)},
            {"channel", segmentation::channel_name(settings.proposals.grow.channel)},
            {"tolerance", settings.proposals.grow.tolerance},
            {"min_pixels", settings.proposals.min_pixels}}),
      revision);
  project.put_node(edit, group);
  for (const ObjectNode& object : made) project.put_node(edit, object);
  if (!made.empty()) put_membership(project, edit, settings.scan_id, membership);
  refresh_figures(project, edit, tree, figures);
  result.command_id = edit.command_id();
  edit.commit(dump({{"group", group.id}, {"proposals", made.size()}, {"pixels", proposed.pixels}}));
  return result;
}

SelectResult select_region(Project& project, const SelectSettings& settings) {
  const std::int64_t revision = project.revision();
  const std::string where = "scan " + std::to_string(settings.scan_id);
  const StoredScanSummary summary = require_scan(project, settings.scan_id);
  const int rows = summary.summary.rows, columns = summary.summary.columns;
  if (settings.seed_row < 0 || settings.seed_row >= rows || settings.seed_col < 0 ||
      settings.seed_col >= columns) {
    refuse(where, "seed (" + std::to_string(settings.seed_row) + ", " +
                      std::to_string(settings.seed_col) + ") is outside the " +
                      std::to_string(rows) + " × " + std::to_string(columns) + " grid");
  }
  const Prepared prepared = prepare(project, settings.scan_id, settings.range_noise);
  const acquisition::Scan& scan = prepared.scan;
  const segmentation::SegmentationGrid& grid = prepared.grid;
  const std::vector<std::uint8_t> open = segmentation::open_pixels(
      grid, settings.constraints,
      taken_mask(load_membership(project, settings.scan_id, scan.pixel_count())));
  segmentation::RegionGrower grower(grid);
  const segmentation::GrowResult grown =
      grower.grow(scan.index(settings.seed_row, settings.seed_col), settings.grow, open);
  const segmentation::PixelSet before = load_selection(project, settings.scan_id);
  segmentation::PixelSet selection;
  switch (settings.mode) {
    case SelectMode::kReplace:
      selection = grown.pixels;
      break;
    case SelectMode::kAdd:
      selection = segmentation::unite(before, grown.pixels);
      break;
    case SelectMode::kSubtract:
      selection = segmentation::subtract(before, grown.pixels);
      break;
  }
  Project::Edit edit = project.begin_command("select", dump(select_json(settings)), revision);
  put_selection(project, edit, settings.scan_id, grid.shape, selection);
  SelectResult result{edit.command_id(), grown.pixels.size(), selection.size(), grown.seed_open};
  edit.commit(dump({{"region_pixels", result.region_pixels},
                    {"selected_pixels", result.selected_pixels},
                    {"seed_open", result.seed_open}}));
  return result;
}

NodeCommandResult commit_selection(Project& project, const CommitSettings& settings) {
  const std::int64_t revision = project.revision();
  const std::string where = "scan " + std::to_string(settings.scan_id);
  require_name(settings.name);
  Tree tree = load_tree(project);
  require_group(tree, settings.parent);
  // The grid's size from the summary: compute_figures decodes the scan itself.
  const StoredScanSummary stored = require_scan(project, settings.scan_id);
  const segmentation::PixelSet selection = load_selection(project, settings.scan_id);
  std::vector<std::uint32_t> membership =
      load_membership(project, settings.scan_id,
                      static_cast<std::size_t>(stored.summary.rows) * stored.summary.columns);
  ObjectNode node;
  node.id = fresh_ids(project, 1);
  node.name = settings.name;
  node.parent = settings.parent;
  std::size_t taken = 0;
  for (const std::uint32_t p : selection) {
    if (membership[p] != 0) continue;  // another object's since the selection grew
    membership[p] = static_cast<std::uint32_t>(node.id);
    ++taken;
  }
  if (taken == 0) refuse(where, "the selection is empty: grow a region first");
  tree.emplace(node.id, node);
  const auto figures = compute_figures(project, tree, {{settings.scan_id, membership}});
  Project::Edit edit = project.begin_command("commit",
                                             dump({{"scan", settings.scan_id},
                                                   {"name", settings.name},
                                                   {"parent", parent_json(settings.parent)}}),
                                             revision);
  project.put_node(edit, node);
  put_membership(project, edit, settings.scan_id, membership);
  project.remove_layer(edit, settings.scan_id, layer::kSelection);
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", node.id}, {"points", taken}}));
  return {command_id, node.id};
}

NodeCommandResult group_nodes(Project& project, const GroupSettings& settings) {
  const std::int64_t revision = project.revision();
  require_name(settings.name);
  Tree tree = load_tree(project);
  require_group(tree, settings.parent);
  ObjectNode group;
  group.id = fresh_ids(project, 1);
  group.name = settings.name;
  group.kind = NodeKind::kGroup;
  group.parent = settings.parent;
  for (const std::int64_t child : settings.children) {
    require_node(tree, child);
    if (settings.parent && is_at_or_above(tree, child, *settings.parent)) {
      refuse("node " + std::to_string(child), "cannot go into a group below itself");
    }
  }
  tree.emplace(group.id, group);
  for (const std::int64_t child : settings.children) tree.at(child).parent = group.id;
  const auto figures = compute_figures(project, tree, {});
  Project::Edit edit = project.begin_command("group",
                                             dump({{"name", settings.name},
                                                   {"parent", parent_json(settings.parent)},
                                                   {"children", settings.children}}),
                                             revision);
  project.put_node(edit, group);
  for (const std::int64_t child : settings.children) project.put_node(edit, tree.at(child));
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", group.id}}));
  return {command_id, group.id};
}

NodeCommandResult edit_node(Project& project, const NodeEdit& change) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  ObjectNode node = require_node(tree, change.node);
  nlohmann::json settings = {{"node", change.node}};
  if (change.name) {
    require_name(*change.name);
    node.name = *change.name;
    settings["name"] = *change.name;
  }
  if (change.hidden) {
    node.hidden = *change.hidden;
    settings["hidden"] = *change.hidden;
  }
  if (change.parent) {
    require_group(tree, *change.parent);
    if (*change.parent && is_at_or_above(tree, change.node, **change.parent)) {
      refuse("node " + std::to_string(change.node), "cannot go into a group below itself");
    }
    node.parent = *change.parent;
    settings["parent"] = parent_json(*change.parent);
  }
  tree[node.id] = node;
  const auto figures =
      change.parent ? compute_figures(project, tree, {}) : std::map<std::int64_t, Figures>{};
  Project::Edit edit = project.begin_command("edit", dump(settings), revision);
  project.put_node(edit, node);
  if (change.parent) refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", node.id}}));
  return {command_id, node.id};
}

std::vector<ObjectNode> node_figures_after_moving(
    const Project& project, const std::map<std::int64_t, Eigen::Isometry3d>& poses) {
  const Tree tree = load_tree(project);
  if (tree.empty()) return {};
  return with_new_figures(tree, compute_figures(project, tree, {}, poses));
}

UngroupResult ungroup_node(Project& project, std::int64_t group) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  const ObjectNode dissolved = require_node(tree, group);
  if (dissolved.kind != NodeKind::kGroup) {
    refuse("node " + std::to_string(group),
           "is an object, not a group: there is nothing to ungroup");
  }
  UngroupResult result;
  for (auto& [id, node] : tree) {
    if (node.parent != group) continue;
    node.parent = dissolved.parent;
    result.children.push_back(id);
  }
  // The ancestors keep the same descendants' points: no figure changes.
  Project::Edit edit = project.begin_command("ungroup", dump({{"node", group}}), revision);
  for (const std::int64_t child : result.children) project.put_node(edit, tree.at(child));
  project.remove_node(edit, group);
  result.command_id = edit.command_id();
  edit.commit(dump({{"node", group}, {"children", result.children}}));
  return result;
}

NodeCommandResult merge_objects(Project& project, const MergeSettings& settings) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  if (settings.objects.size() < 2) refuse("merge", "needs two objects or more");
  std::unordered_set<std::uint32_t> absorbed;
  for (const std::int64_t id : settings.objects) {
    if (require_node(tree, id).kind != NodeKind::kObject) {
      refuse("node " + std::to_string(id), "is a group: only objects can be merged");
    }
    if (id != settings.objects.front() && !absorbed.insert(static_cast<std::uint32_t>(id)).second) {
      refuse("node " + std::to_string(id), "is named twice");
    }
  }
  const auto into = static_cast<std::uint32_t>(settings.objects.front());
  if (absorbed.count(into)) refuse("node " + std::to_string(into), "cannot merge into itself");
  const std::map<std::int64_t, std::vector<std::uint32_t>> changed =
      reassign_pixels(project, absorbed, into);
  for (const std::uint32_t id : absorbed) tree.erase(id);
  const auto figures = compute_figures(project, tree, changed);
  Project::Edit edit =
      project.begin_command("merge_objects", dump({{"objects", settings.objects}}), revision);
  for (const std::uint32_t id : absorbed) project.remove_node(edit, id);
  for (const auto& [scan_id, membership] : changed)
    put_membership(project, edit, scan_id, membership);
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", into}, {"merged", settings.objects.size() - 1}}));
  return {command_id, into};
}

NodeCommandResult delete_node(Project& project, const DeleteSettings& settings) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  require_node(tree, settings.node);
  std::vector<std::int64_t> gone;
  for (const auto& [id, node] : tree) {
    if (is_at_or_above(tree, settings.node, id)) gone.push_back(id);
  }
  const std::uint32_t replacement = settings.points == DeletedPoints::kToPool ? 0 : kDeletedPoints;
  const std::unordered_set<std::uint32_t> gone_ids(gone.begin(), gone.end());
  const std::map<std::int64_t, std::vector<std::uint32_t>> changed =
      reassign_pixels(project, gone_ids, replacement);
  for (const std::int64_t id : gone) tree.erase(id);
  const auto figures = compute_figures(project, tree, changed);
  Project::Edit edit = project.begin_command(
      "delete",
      dump({{"node", settings.node},
            {"points", settings.points == DeletedPoints::kToPool ? "pool" : "deleted"}}),
      revision);
  for (const std::int64_t id : gone) project.remove_node(edit, id);
  for (const auto& [scan_id, membership] : changed)
    put_membership(project, edit, scan_id, membership);
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"nodes", gone}}));
  return {command_id, settings.node};
}

}  // namespace scanbench::modeling
