#include "modeling/selection_commands.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <unordered_set>

#include "core/errors.hpp"
#include "modeling/carried_objects.hpp"
#include "modeling/command_json.hpp"
#include "modeling/node_tree.hpp"
#include "modeling/object_carry.hpp"
#include "modeling/scan_cache.hpp"
#include "modeling/scan_overlaps.hpp"
#include "modeling/store/typed_layers.hpp"
#include "registration/prepared_scan.hpp"
#include "segmentation/pixel_set.hpp"

namespace scanbench::modeling {

namespace {

// "`base` N", `base` cut (between UTF-8 characters) so that the name fits
// kMaxNodeNameBytes.
std::string numbered_name(const std::string& base, std::size_t number) {
  const std::string digits = std::to_string(number);
  std::size_t keep = std::min(base.size(), store::kMaxNodeNameBytes - 1 - digits.size());
  while (keep > 0 && keep < base.size() && (static_cast<unsigned char>(base[keep]) & 0xC0) == 0x80)
    --keep;
  // Appended apart: GCC 12 warns falsely on chains of std::string operator+ at -O3.
  std::string name(base, 0, keep);
  name += ' ';
  name += digits;
  return name;
}

void put_selection(store::Project& project, store::Project::Edit& edit, std::int64_t scan_id,
                   const segmentation::GridShape& shape, const segmentation::PixelSet& selection) {
  if (selection.empty()) {
    project.remove_layer(edit, scan_id, store::layer::kSelection);
    return;
  }
  const std::vector<std::uint8_t> mask = segmentation::to_mask(shape, selection);
  project.put_layer(
      edit, scan_id,
      store::encode_layer<std::uint8_t>(store::layer::kSelection, store::ElementType::kU8, mask));
}

// Pixels of `scan_id` that a command assigned where they were drawn: no
// longer carried. The layer as it then is, none when the scan has none.
std::optional<std::vector<std::uint8_t>> drawn_there(const store::Project& project,
                                                     std::int64_t scan_id,
                                                     const segmentation::PixelSet& pixels) {
  auto carried =
      project.load_layer<std::uint8_t>(scan_id, store::layer::kCarried, store::ElementType::kU8);
  if (!carried) return std::nullopt;
  for (const std::uint32_t p : pixels) (*carried)[p] = 0;
  return carried;
}

void put_carried(store::Project& project, store::Project::Edit& edit, std::int64_t scan_id,
                 const std::vector<std::uint8_t>& carried) {
  project.put_layer(
      edit, scan_id,
      store::encode_layer<std::uint8_t>(store::layer::kCarried, store::ElementType::kU8, carried));
}

store::StoredScanSummary require_scan(const store::Project& project, std::int64_t scan_id) {
  for (const store::StoredScanSummary& stored : project.scans()) {
    if (stored.id == scan_id) return stored;
  }
  refuse("scan " + std::to_string(scan_id), "no such scan");
}

// 1 where an object owns the pixel or it is deleted: closed to growing.
std::vector<std::uint8_t> taken_mask(const std::vector<std::uint32_t>& membership) {
  std::vector<std::uint8_t> taken(membership.size());
  for (std::size_t i = 0; i < taken.size(); ++i) taken[i] = membership[i] != 0;
  return taken;
}

// Growing, lassos, barriers and parts work on a range image, which an
// unstructured cloud does not have.
void require_grid(bool scattered, std::int64_t scan_id) {
  if (scattered) {
    refuse("scan " + std::to_string(scan_id),
           "is an unstructured cloud (imported without a scan grid): growing a region, lassos, "
           "barriers and parts need a range image");
  }
}

// The scan, its geometry (refused when missing) and the grid a region grows on.
struct Prepared {
  acquisition::Scan scan;
  acquisition::ScanGeometry geometry;
  segmentation::SegmentationGrid grid;
};

Prepared prepare(const store::Project& project, std::int64_t scan_id,
                 const std::optional<acquisition::RangeNoise>& noise) {
  Prepared p;
  p.scan = project.load_scan(scan_id);
  require_grid(p.scan.is_scattered(), scan_id);
  std::optional<acquisition::ScanGeometry> geometry = store::load_geometry(project, scan_id);
  if (!geometry) {
    refuse("scan " + std::to_string(scan_id), "has no geometry: run `scanbench geometry` first");
  }
  p.geometry = std::move(*geometry);
  segmentation::GridSettings settings;
  settings.range_noise = noise.value_or(p.geometry.range_noise);
  p.grid = segmentation::prepare_grid(p.scan, p.geometry, settings);
  return p;
}

}  // namespace

SeparateResult separate_object(store::Project& project, const SeparateSettings& settings) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  const store::ObjectNode object = require_node(tree, settings.node);
  if (object.kind != store::NodeKind::kObject) {
    refuse("node " + std::to_string(settings.node), "is a group: only objects own pixels");
  }
  const acquisition::Scan scan = project.load_scan(settings.scan_id);
  require_grid(scan.is_scattered(), settings.scan_id);
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
  std::vector<store::ObjectNode> made;
  std::int64_t next = fresh_ids(project, parts.empty() ? 0 : parts.size() - 1);
  for (std::size_t k = 1; k < parts.size(); ++k) {
    store::ObjectNode part = object;
    part.id = next++;
    part.name = numbered_name(object.name, k + 1);
    for (const std::uint32_t p : parts[k]) membership[p] = static_cast<std::uint32_t>(part.id);
    tree.emplace(part.id, part);
    made.push_back(part);
    result.nodes.push_back(part.id);
  }
  // The user split the object where it lies in this scan: its points there
  // are drawn from now on, so a registration carries the parts as they are.
  const std::optional<std::vector<std::uint8_t>> drawn =
      drawn_there(project, settings.scan_id, owned);
  const auto figures = compute_figures(project, tree, {{settings.scan_id, membership}});
  store::Project::Edit edit = project.begin_command(
      "separate", dump({{"node", settings.node}, {"scan", settings.scan_id}}), revision);
  for (const store::ObjectNode& part : made) project.put_node(edit, part);
  if (!made.empty()) put_membership(project, edit, settings.scan_id, membership);
  if (drawn) put_carried(project, edit, settings.scan_id, *drawn);
  refresh_figures(project, edit, tree, figures);
  result.command_id = edit.command_id();
  edit.commit(dump({{"nodes", result.nodes}}));
  return result;
}

SeparateResult propose_objects(store::Project& project, const ProposeSettings& settings) {
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
  store::ObjectNode group;
  group.id = fresh_ids(project, 1 + proposed.regions.size());
  group.name = settings.group_name;
  group.kind = store::NodeKind::kGroup;
  group.parent = settings.parent;
  tree.emplace(group.id, group);
  SeparateResult result;
  std::vector<store::ObjectNode> made;
  for (std::size_t k = 0; k < proposed.regions.size(); ++k) {
    store::ObjectNode object;
    object.id = group.id + 1 + static_cast<std::int64_t>(k);
    object.name = "proposal " + std::to_string(k + 1);
    object.parent = group.id;
    for (const std::uint32_t px : proposed.regions[k])
      membership[px] = static_cast<std::uint32_t>(object.id);
    tree.emplace(object.id, object);
    made.push_back(object);
    result.nodes.push_back(object.id);
  }
  segmentation::PixelSet proposed_pixels;
  for (const segmentation::PixelSet& region : proposed.regions)
    proposed_pixels.insert(proposed_pixels.end(), region.begin(), region.end());
  const std::optional<std::vector<std::uint8_t>> drawn =
      drawn_there(project, settings.scan_id, proposed_pixels);
  const auto figures = compute_figures(project, tree, {{settings.scan_id, membership}});
  store::Project::Edit edit = project.begin_command(
      "propose",
      dump({{"scan", settings.scan_id},
            {"group", settings.group_name},
            {"parent", parent_json(settings.parent)},
            {"channel", segmentation::channel_name(settings.proposals.grow.channel)},
            {"tolerance", settings.proposals.grow.tolerance},
            {"min_pixels", settings.proposals.min_pixels}}),
      revision);
  project.put_node(edit, group);
  for (const store::ObjectNode& object : made) project.put_node(edit, object);
  if (!made.empty()) put_membership(project, edit, settings.scan_id, membership);
  if (drawn) put_carried(project, edit, settings.scan_id, *drawn);
  refresh_figures(project, edit, tree, figures);
  result.command_id = edit.command_id();
  edit.commit(dump({{"group", group.id}, {"proposals", made.size()}, {"pixels", proposed.pixels}}));
  return result;
}

// Why the seed of `settings` cannot grow a region: the first condition that
// closes it, in the words of the tools.
std::string seed_refusal(const segmentation::SegmentationGrid& grid, const SelectSettings& settings,
                         const std::vector<std::uint32_t>& membership, std::size_t seed,
                         const segmentation::GrowResult& grown) {
  if (!grid.usable[seed]) return "the scan has no usable point there (no return, or a mixed pixel)";
  if (membership[seed] == store::kDeletedPoints) return "its point was deleted";
  if (membership[seed] != 0) return "object " + std::to_string(membership[seed]) + " owns it";
  if (segmentation::open_pixels(grid, {settings.constraints.lasso, {}}, {})[seed] == 0)
    return "it lies outside the lasso";
  if (!grown.seed_open) return "it lies on a barrier";
  switch (settings.grow.channel) {
    case segmentation::Channel::kNormal:
      return "it has no normal (an edge or a crease): click beside it, or grow on range";
    case segmentation::Channel::kColor:
      return "the scan has no colour";
    case segmentation::Channel::kIntensity:
      return "it has no intensity";
    case segmentation::Channel::kRange:
      break;
  }
  return "it cannot grow on " + std::string(segmentation::channel_name(settings.grow.channel));
}

SelectResult select_region(const store::Project& project, const SelectSettings& settings,
                           segmentation::PixelSet& selection) {
  const std::string where = "scan " + std::to_string(settings.scan_id);
  const store::StoredScanSummary summary = require_scan(project, settings.scan_id);
  require_grid(summary.summary.scattered, settings.scan_id);
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
  const std::vector<std::uint32_t> membership =
      load_membership(project, settings.scan_id, scan.pixel_count());
  const std::vector<std::uint8_t> open =
      segmentation::open_pixels(grid, settings.constraints, taken_mask(membership));
  segmentation::RegionGrower grower(grid);
  const std::size_t seed = scan.index(settings.seed_row, settings.seed_col);
  const segmentation::GrowResult grown = grower.grow(seed, settings.grow, open);
  SelectResult result{grown.pixels.size(), 0, grown.seed_open && !grown.seed_lacks_channel, {}};
  if (!result.seed_open) {
    result.refused = seed_refusal(grid, settings, membership, seed, grown);
    result.region_pixels = 0;
    result.selected_pixels = selection.size();
    return result;
  }
  switch (settings.mode) {
    case SelectMode::kReplace:
      selection = grown.pixels;
      break;
    case SelectMode::kAdd:
      selection = segmentation::unite(selection, grown.pixels);
      break;
    case SelectMode::kSubtract:
      selection = segmentation::subtract(selection, grown.pixels);
      break;
  }
  result.selected_pixels = selection.size();
  return result;
}

segmentation::PixelSet kept_selection(const store::Project& project, std::int64_t scan_id) {
  const auto stored =
      project.load_layer<std::uint8_t>(scan_id, store::layer::kSelection, store::ElementType::kU8);
  return stored ? segmentation::from_mask(*stored) : segmentation::PixelSet{};
}

std::int64_t keep_selections(store::Project& project,
                             const std::map<std::int64_t, segmentation::PixelSet>& selections) {
  std::map<std::int64_t, segmentation::GridShape> shapes;
  nlohmann::json scans = nlohmann::json::object();
  for (const auto& [scan_id, selection] : selections) {
    const store::StoredScanSummary stored = require_scan(project, scan_id);
    shapes[scan_id] = {stored.summary.rows, stored.summary.columns};
    for (const std::uint32_t p : selection) {
      if (p >= static_cast<std::size_t>(stored.summary.rows) * stored.summary.columns)
        refuse("scan " + std::to_string(scan_id), "the selection has a pixel outside the grid");
    }
    scans[std::to_string(scan_id)] = selection.size();
  }
  store::Project::Edit edit = project.begin_command("keep_selection", dump({{"scans", scans}}));
  for (const auto& [scan_id, selection] : selections)
    put_selection(project, edit, scan_id, shapes.at(scan_id), selection);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"scans", scans}}));
  return command_id;
}

namespace {

// What a commit carries into scans besides where it was drawn: their
// changed carried layers, and how many points joined.
struct CarriedInto {
  std::map<std::int64_t, std::vector<std::uint8_t>> carried;
  std::size_t points = 0;
};

bool has_geometry(const store::Project& project, std::int64_t scan_id) {
  const std::vector<std::string> layers = project.layer_names(scan_id);
  return std::find(layers.begin(), layers.end(), store::layer::kNormal) != layers.end();
}

// The scans with geometry, by id, whose stored bounds reach the world box
// of object `node` as drawn in `drawn` (scan id → its membership with the
// object's pixels taken; each has geometry).
std::vector<std::int64_t> scans_reaching(
    const store::Project& project, const std::map<std::int64_t, std::vector<std::uint32_t>>& drawn,
    std::uint32_t node, ScanCache& cache) {
  std::vector<std::int64_t> drawn_ids;
  for (const auto& [scan_id, membership] : drawn) drawn_ids.push_back(scan_id);
  cache.plan(drawn_ids);
  Eigen::AlignedBox3d bounds;
  for (const auto& [scan_id, membership] : drawn) {
    const std::shared_ptr<const LoadedScan> loaded = cache.get(scan_id);
    const registration::PreparedScan& source = loaded->prepared;
    for (std::size_t i = 0; i < membership.size(); ++i) {
      if (membership[i] == node && source.in_model[i])
        bounds.extend(loaded->scan.T_world_scan * source.points[i].cast<double>());
    }
  }
  std::vector<std::int64_t> out;
  for (const store::StoredScanSummary& stored : project.scans()) {
    if (drawn.count(stored.id) != 0 ||
        (bounds_reach(stored, bounds) && has_geometry(project, stored.id)))
      out.push_back(stored.id);
  }
  return out;
}

// Carries object `node`, drawn in the scans of `memberships` (scan id → its
// membership with the object's pixels taken), into every scan with
// geometry whose bounds reach the object's: each takes, where its points
// are still to be segmented, those that sample the surface the object
// covers in the other drawn scans, and with `grow` those it grows to there
// (object_carry.hpp). `memberships` gains the scans that take some;
// `carried` holds each changed scan's carried layer, starting from
// `drawn_carried` for the drawn scans. Scans come through a ScanCache
// within the memory limit: each target with the drawn scans it takes from.
CarriedInto carry_into_scans(const store::Project& project, std::uint32_t node,
                             std::map<std::int64_t, std::vector<std::uint32_t>>& memberships,
                             std::map<std::int64_t, std::vector<std::uint8_t>> drawn_carried,
                             const CommitSettings& settings) {
  CarriedInto out;
  core::Progress quiet;
  ScanCache cache(project, memory_limit_or_default(std::nullopt), 0, "commit", quiet);
  // The drawn scans with geometry are the sources (a scan without has no
  // surfaces to carry from).
  std::map<std::int64_t, std::vector<std::uint32_t>> drawn;
  for (const auto& [scan_id, membership] : memberships) {
    if (has_geometry(project, scan_id)) drawn.emplace(scan_id, membership);
  }
  if (drawn.empty()) {
    out.carried = std::move(drawn_carried);
    return out;
  }
  std::vector<std::int64_t> targets;
  std::vector<std::int64_t> order;
  for (const std::int64_t t : scans_reaching(project, drawn, node, cache)) {
    if (drawn.size() == 1 && drawn.count(t) != 0) continue;  // nothing to take from
    targets.push_back(t);
    order.push_back(t);
    for (const auto& [from, membership] : drawn) {
      if (from != t) order.push_back(from);
    }
  }
  cache.plan(order);
  CarrySettings carry;
  carry.transfer.noise = settings.range_noise;
  carry.grow = settings.grow;
  for (const std::int64_t t : targets) {
    const std::shared_ptr<const LoadedScan> target = cache.get(t);
    const std::size_t pixels = target->scan.pixel_count();
    const auto own = drawn.find(t);
    std::vector<std::uint32_t> membership =
        own != drawn.end() ? own->second : load_membership(project, t, pixels);
    const auto kept_carried = drawn_carried.find(t);
    std::vector<std::uint8_t> carried = kept_carried != drawn_carried.end()
                                            ? kept_carried->second
                                            : load_carried(project, t, pixels);
    std::vector<std::uint8_t> open = taken_mask(membership);
    for (std::uint8_t& o : open) o = !o;
    std::optional<segmentation::SegmentationGrid> grid;
    if (settings.grow && !target->scan.is_scattered()) {  // a scattered scan has no grid
      segmentation::GridSettings grid_settings;
      grid_settings.range_noise = settings.range_noise.value_or(target->geometry.range_noise);
      grid = segmentation::prepare_grid(target->scan, target->geometry, grid_settings);
    }
    std::size_t joined = 0;
    for (const auto& [from, source_membership] : drawn) {
      if (from == t) continue;
      const std::shared_ptr<const LoadedScan> source = cache.get(from);
      std::vector<std::uint32_t> labels(source_membership.size(), 0);
      for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = source_membership[i] == node;
      const segmentation::PixelSet joins = carry_object(
          {&source->prepared, source->scan.T_world_scan, labels},
          {&target->prepared, target->scan.T_world_scan, grid ? &*grid : nullptr, open}, carry);
      for (const std::uint32_t q : joins) {
        membership[q] = node;
        carried[q] = 1;
        open[q] = 0;
      }
      joined += joins.size();
    }
    out.points += joined;
    if (joined != 0) {
      out.carried.emplace(t, std::move(carried));
      memberships[t] = std::move(membership);
    }
  }
  // The drawn scans that took nothing keep their carried layers as drawn.
  for (auto& [scan_id, carried] : drawn_carried) out.carried.emplace(scan_id, std::move(carried));
  return out;
}

}  // namespace

NodeCommandResult commit_selections(
    store::Project& project, const CommitSettings& settings,
    const std::map<std::int64_t, segmentation::PixelSet>& selections) {
  const std::int64_t revision = project.revision();
  require_name(settings.name);
  Tree tree = load_tree(project);
  require_group(tree, settings.parent);
  store::ObjectNode node;
  node.id = fresh_ids(project, 1);
  node.name = settings.name;
  node.parent = settings.parent;
  const auto owner = static_cast<std::uint32_t>(node.id);
  // Per drawn scan: its membership with the selection taken, and its
  // carried layer with those pixels marked drawn (none without one).
  std::map<std::int64_t, std::vector<std::uint32_t>> changed;
  std::map<std::int64_t, std::vector<std::uint8_t>> drawn_carried;
  std::size_t taken_points = 0;
  for (const auto& [scan_id, selection] : selections) {
    if (selection.empty()) continue;
    const std::string where = "scan " + std::to_string(scan_id);
    // The grid's size from the summary: compute_figures decodes the scan itself.
    const store::StoredScanSummary stored = require_scan(project, scan_id);
    std::vector<std::uint32_t> membership = load_membership(
        project, scan_id, static_cast<std::size_t>(stored.summary.rows) * stored.summary.columns);
    segmentation::PixelSet taken;
    for (const std::uint32_t p : selection) {
      if (p >= membership.size())
        refuse(where, "the selection has a pixel outside the grid: it was grown on another scan");
      if (membership[p] != 0) continue;  // another object's since the selection grew
      membership[p] = owner;
      taken.push_back(p);
    }
    if (taken.empty()) continue;
    taken_points += taken.size();
    changed.emplace(scan_id, std::move(membership));
    if (auto drawn = drawn_there(project, scan_id, taken))
      drawn_carried.emplace(scan_id, std::move(*drawn));
  }
  if (changed.empty()) {
    const std::string where = selections.size() == 1
                                  ? "scan " + std::to_string(selections.begin()->first)
                                  : "the selection";
    refuse(where, "the selection is empty: grow a region first");
  }
  tree.emplace(node.id, node);
  std::vector<std::int64_t> drawn_scans;
  for (const auto& [scan_id, membership] : changed) drawn_scans.push_back(scan_id);
  CarriedInto others;
  if (settings.other_scans) {
    others = carry_into_scans(project, owner, changed, std::move(drawn_carried), settings);
  } else {
    others.carried = std::move(drawn_carried);
  }
  const auto figures = compute_figures(project, tree, changed);
  // The journal names the first drawn scan; re-carrying after a
  // registration reads only the channel and noise (carried_objects.hpp).
  CommitSettings recorded = settings;
  recorded.scan_id = drawn_scans.front();
  store::Project::Edit edit = project.begin_command("commit", settings_to_json(recorded), revision);
  project.put_node(edit, node);
  for (const auto& [scan_id, scan_membership] : changed)
    put_membership(project, edit, scan_id, scan_membership);
  for (const auto& [scan_id, carried] : others.carried)
    put_carried(project, edit, scan_id, carried);
  for (const auto& [scan_id, selection] : selections)
    project.remove_layer(edit, scan_id, store::layer::kSelection);
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", node.id},
                    {"points", taken_points},
                    {"scans", drawn_scans},
                    {"other_scans_points", others.points}}));
  return {command_id, node.id};
}

NodeCommandResult commit_selection(store::Project& project, const CommitSettings& settings,
                                   const segmentation::PixelSet& selection) {
  return commit_selections(project, settings, {{settings.scan_id, selection}});
}

}  // namespace scanbench::modeling
