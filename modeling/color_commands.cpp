#include "modeling/color_commands.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "acquisition/color_space.hpp"
#include "core/errors.hpp"
#include "modeling/command_json.hpp"
#include "modeling/store/layer_store.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {

namespace {

[[noreturn]] void refuse(const std::string& where, const std::string& problem) {
  core::FilePosition position;
  position.detail = where;
  throw core::InputError("", position, problem);
}

std::string node_name(std::int64_t id) {
  return "node " + std::to_string(id);
}

const store::ObjectNode& require_node(const std::vector<store::ObjectNode>& nodes,
                                      std::int64_t id) {
  for (const store::ObjectNode& n : nodes) {
    if (n.id == id) return n;
  }
  refuse(node_name(id), "no such node");
}

// `root` and every node below it.
std::set<std::int64_t> subtree(const std::vector<store::ObjectNode>& nodes, std::int64_t root) {
  std::set<std::int64_t> out{root};
  for (bool grown = true; grown;) {
    grown = false;
    for (const store::ObjectNode& n : nodes) {
      if (n.parent && out.count(*n.parent) && out.insert(n.id).second) grown = true;
    }
  }
  return out;
}

// `target` and the nodes below it that take their transfer from it (none
// on the way up to it sets its own): the points a transfer set on the
// target reaches.
std::set<std::int64_t> inheriting_transfer(const std::vector<store::ObjectNode>& nodes,
                                           std::int64_t target) {
  std::set<std::int64_t> out{target};
  for (bool grown = true; grown;) {
    grown = false;
    for (const store::ObjectNode& n : nodes) {
      if (n.parent && out.count(*n.parent) && !n.color.transfer && out.insert(n.id).second)
        grown = true;
    }
  }
  return out;
}

// Mean and standard deviation of L*a*b* colours.
struct LabStats {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d squares = Eigen::Vector3d::Zero();
  std::size_t count = 0;
  void add(const Eigen::Vector3d& lab) {
    sum += lab;
    squares += lab.cwiseProduct(lab);
    ++count;
  }
  Eigen::Vector3d mean() const { return sum / static_cast<double>(count); }
  Eigen::Vector3d deviation() const {
    const Eigen::Vector3d m = mean();
    return (squares / static_cast<double>(count) - m.cwiseProduct(m)).cwiseMax(0.0).cwiseSqrt();
  }
};

struct ColorLayers {
  std::vector<std::uint8_t> rgb;  // 3 per pixel
  std::optional<std::vector<std::uint32_t>> membership;
};

std::optional<ColorLayers> color_layers(const store::Project& project, std::int64_t scan_id) {
  std::optional<std::vector<std::uint8_t>> rgb =
      project.load_layer<std::uint8_t>(scan_id, store::layer::kRgb, store::ElementType::kU8x3);
  if (!rgb) return std::nullopt;
  return ColorLayers{std::move(*rgb),
                     project.load_layer<std::uint32_t>(scan_id, store::layer::kMembership,
                                                       store::ElementType::kU32)};
}

std::array<std::uint8_t, 3> pixel_rgb(const ColorLayers& layers, std::size_t i) {
  return {layers.rgb[3 * i], layers.rgb[3 * i + 1], layers.rgb[3 * i + 2]};
}

// The colours of the points the nodes in `owners` own, over every scan:
// as shown (`shown`) or after the scans' corrections only.
LabStats node_colors(const store::Project& project, const ColorPipeline& pipeline,
                     const std::set<std::int64_t>& owners, bool shown) {
  LabStats stats;
  for (const store::StoredScanSummary& scan : project.scans()) {
    const std::optional<ColorLayers> layers = color_layers(project, scan.id);
    if (!layers || !layers->membership) continue;
    const std::vector<std::uint32_t>& owner = *layers->membership;
    for (std::size_t i = 0; i < owner.size(); ++i) {
      if (owner[i] == 0 || !owners.count(owner[i])) continue;
      const std::array<std::uint8_t, 3> rgb = pixel_rgb(*layers, i);
      stats.add(shown ? acquisition::srgb_to_lab(pipeline.shown(scan.id, owner[i], rgb))
                      : pipeline.corrected_lab(scan.id, rgb));
    }
  }
  return stats;
}

LabStats region_colors(const store::Project& project, const ColorPipeline& pipeline,
                       const PixelRect& region) {
  const std::string where = "scan " + std::to_string(region.scan_id);
  const acquisition::Scan scan = project.load_scan(region.scan_id);  // throws when missing
  if (scan.is_scattered()) {
    refuse(where,
           "is an unstructured cloud (imported without a scan grid): a region of its "
           "range image is not a region of the scene; match an object instead");
  }
  if (region.row_begin < 0 || region.col_begin < 0 || region.row_end > scan.rows ||
      region.col_end > scan.columns || region.row_begin >= region.row_end ||
      region.col_begin >= region.col_end) {
    refuse(where, "the region rows " + std::to_string(region.row_begin) + "…" +
                      std::to_string(region.row_end) + ", columns " +
                      std::to_string(region.col_begin) + "…" + std::to_string(region.col_end) +
                      " is empty or outside the " + std::to_string(scan.rows) + " × " +
                      std::to_string(scan.columns) + " grid");
  }
  if (!scan.has_color()) refuse(where, "the scan has no colour");
  const std::optional<std::vector<std::uint32_t>> membership = project.load_layer<std::uint32_t>(
      region.scan_id, store::layer::kMembership, store::ElementType::kU32);
  const std::optional<acquisition::ScanGeometry> geometry =
      store::load_geometry(project, region.scan_id);
  LabStats stats;
  for (int row = region.row_begin; row < region.row_end; ++row) {
    for (int col = region.col_begin; col < region.col_end; ++col) {
      // Only what the model shows: in the model (valid, not a mixed pixel)
      // and not deleted.
      const std::size_t i = scan.index(row, col);
      if (!scan.valid[i] || (geometry && !acquisition::in_model(scan, *geometry, i))) continue;
      const std::uint32_t owner = membership ? (*membership)[i] : 0;
      if (owner == store::kDeletedPoints) continue;
      const std::array<std::uint8_t, 3> rgb = {scan.rgb[3 * i], scan.rgb[3 * i + 1],
                                               scan.rgb[3 * i + 2]};
      stats.add(acquisition::srgb_to_lab(pipeline.shown(region.scan_id, owner, rgb)));
    }
  }
  return stats;
}

ColorPipeline pipeline_of(const store::Project& project,
                          const std::vector<store::ObjectNode>& nodes) {
  return ColorPipeline(project.scan_color_corrections(), resolve_color_edits(nodes));
}

nlohmann::json edit_json(const store::ColorEdit& edit) {
  const std::string text = to_json(edit);
  return text.empty() ? nlohmann::json::object() : nlohmann::json::parse(text);
}

}  // namespace

NodeCommandResult recolor_object(store::Project& project, const RecolorSettings& settings) {
  const std::int64_t revision = project.revision();
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  store::ObjectNode node = require_node(nodes, settings.node);
  if (const std::string problem = store::check_color_edit(settings.set); !problem.empty())
    refuse(node_name(settings.node), problem);
  if (settings.reset) node.color = {};
  const store::ColorEdit& set = settings.set;
  if (set.brightness) node.color.brightness = set.brightness;
  if (set.contrast) node.color.contrast = set.contrast;
  if (set.gamma) node.color.gamma = set.gamma;
  if (set.hue_deg) node.color.hue_deg = set.hue_deg;
  if (set.saturation) node.color.saturation = set.saturation;
  if (set.transfer) node.color.transfer = set.transfer;
  nlohmann::json json = {{"node", settings.node}, {"reset", settings.reset}};
  json["set"] = edit_json(set);
  store::Project::Edit edit = project.begin_command("recolor", dump(json), revision);
  project.put_node(edit, node);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", node.id}, {"color", edit_json(node.color)}}));
  return {command_id, node.id};
}

CloneResult clone_color(store::Project& project, const CloneSettings& settings) {
  const int sources = (settings.source_node ? 1 : 0) + (settings.source_region ? 1 : 0) +
                      (settings.source_color ? 1 : 0);
  if (sources != 1) refuse("clone", "give exactly one source: an object, a region or a colour");
  const std::int64_t revision = project.revision();
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  store::ObjectNode target = require_node(nodes, settings.target);
  const ColorPipeline pipeline = pipeline_of(project, nodes);
  nlohmann::json json = {{"target", settings.target}, {"paint", settings.paint}};

  LabStats source;
  if (settings.source_node) {
    require_node(nodes, *settings.source_node);
    if (subtree(nodes, settings.target).count(*settings.source_node) ||
        subtree(nodes, *settings.source_node).count(settings.target))
      refuse(node_name(*settings.source_node), "source and target must not contain each other");
    source = node_colors(project, pipeline, subtree(nodes, *settings.source_node), true);
    json["source_node"] = *settings.source_node;
  } else if (settings.source_region) {
    const PixelRect& r = *settings.source_region;
    source = region_colors(project, pipeline, r);
    json["source_region"] = {{"scan", r.scan_id},
                             {"rows", {r.row_begin, r.row_end}},
                             {"columns", {r.col_begin, r.col_end}}};
  } else {
    const std::array<std::uint8_t, 3>& c = *settings.source_color;
    source.add(acquisition::srgb_to_lab(c));
    json["source_color"] = {c[0], c[1], c[2]};
  }
  if (source.count == 0) refuse("clone", "the source has no coloured points");
  const LabStats own =
      node_colors(project, pipeline, inheriting_transfer(nodes, settings.target), false);
  if (own.count == 0) refuse(node_name(settings.target), "the target has no coloured points");

  // Per channel: the target's mean onto the source's, its spread scaled to
  // the source's; painting keeps the lightness spread and flattens a*b*.
  const bool paint = settings.paint || settings.source_color.has_value();
  store::LabTransfer transfer;
  const Eigen::Vector3d target_sd = own.deviation().cwiseMax(1e-3);
  for (int c = 0; c < 3; ++c) {
    double scale = paint ? (c == 0 ? 1.0 : 0.0) : source.deviation()[c] / target_sd[c];
    scale = std::clamp(scale, 0.0, 10.0);
    transfer.scale[c] = scale;
    transfer.offset[c] = source.mean()[c] - scale * own.mean()[c];
  }
  target.color = store::ColorEdit{0.0, 1.0, 1.0, 0.0, 1.0, transfer};
  store::Project::Edit edit = project.begin_command("clone", dump(json), revision);
  project.put_node(edit, target);
  CloneResult out{edit.command_id(), target.id, source.count, own.count, transfer};
  edit.commit(dump({{"node", target.id},
                    {"source_points", out.source_points},
                    {"target_points", out.target_points},
                    {"color", edit_json(target.color)}}));
  return out;
}

}  // namespace scanbench::modeling
