#include "render/render_model.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "acquisition/geometry/scan_geometry.hpp"
#include "core/errors.hpp"
#include "modeling/color_pipeline.hpp"
#include "modeling/lod/splat_shape.hpp"
#include "modeling/shown_nodes.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::render {

namespace {

// Scan `id`'s geometry; refused, naming the scan, when it has none.
acquisition::ScanGeometry require_geometry(const store::Project& project, std::int64_t id,
                                           const std::string& name) {
  std::optional<acquisition::ScanGeometry> geometry = store::load_geometry(project, id);
  if (geometry) return std::move(*geometry);
  core::FilePosition position;
  position.detail = "scan " + std::to_string(id) + " (" + name + ")";
  throw core::InputError(project.path().string(), position,
                         "has no geometry (footprints and normals): run `scanbench geometry`");
}

void gather_scan(const store::Project& project, const store::StoredScanSummary& stored,
                 const RenderModelSettings& settings, const std::map<std::int64_t, bool>& shown,
                 const modeling::ColorPipeline& colors, const Eigen::Vector3d& origin,
                 RenderPoints& p, RenderModelCounts& counts) {
  const acquisition::Scan scan = project.load_scan(stored.id);
  const acquisition::ScanGeometry geometry = require_geometry(project, stored.id, scan.name);
  const auto keep = settings.merged_only
                        ? project.load_layer<std::uint8_t>(stored.id, store::layer::kKeep,
                                                           store::ElementType::kU8)
                        : std::nullopt;
  const auto membership = project.load_layer<std::uint32_t>(stored.id, store::layer::kMembership,
                                                            store::ElementType::kU32);
  std::vector<std::uint8_t> usable(scan.pixel_count());
  for (std::size_t i = 0; i < usable.size(); ++i)
    usable[i] = acquisition::in_model(scan, geometry, i);
  // Room for this scan's points, at least doubling: one copy per scan at
  // most, and none of the many a point at a time would make.
  const auto in_model = static_cast<std::size_t>(std::count(usable.begin(), usable.end(), 1));
  const std::size_t needed = p.size() + in_model;
  if (needed > p.position.capacity()) p.reserve(std::max(needed, 2 * p.position.capacity()));
  const auto [low, high] = acquisition::intensity_range(scan, usable);
  const float spread = high > low ? high - low : 1.0f;
  const lod::ScanSplats splats(scan, settings.max_stretch);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (!usable[i]) continue;
      ++counts.in_model;
      if (keep && (*keep)[i] == 0) {
        ++counts.merged_away;
        continue;
      }
      std::uint32_t owner = membership ? (*membership)[i] : 0;
      if (owner == store::kDeletedPoints) {
        ++counts.deleted;
        continue;
      }
      if (owner != 0) {
        const auto found = shown.find(owner);
        if (found == shown.end()) {
          owner = 0;  // a node no longer in the tree owns nothing
        } else if (!found->second) {
          ++counts.hidden;  // kept, for the renderer to skip until it is shown again
        }
      }
      const float level =
          scan.has_intensity() ? std::clamp((scan.intensity[i] - low) / spread, 0.0f, 1.0f) : 0.5f;
      std::array<std::uint8_t, 4> rgba{};
      if (scan.has_color()) {
        const std::array<std::uint8_t, 3> rgb = colors.shown(
            stored.id, owner, {scan.rgb[3 * i], scan.rgb[3 * i + 1], scan.rgb[3 * i + 2]});
        rgba = {rgb[0], rgb[1], rgb[2], 255};
      } else {
        const auto grey = static_cast<std::uint8_t>(std::lround(255.0f * level));
        rgba = {grey, grey, grey, 255};
      }
      p.position.push_back((acquisition::point_in_world(scan, row, col) - origin).cast<float>());
      const lod::Splat splat = splats.splat(scan, 0, geometry, i, row, col);
      p.normal.push_back(splat.normal);
      p.radii_m.push_back(splat.radii_m);
      p.major_axis.push_back(splat.major_axis);
      p.rgba.push_back(rgba);
      p.intensity.push_back(level);
      p.node.push_back(owner);
    }
  }
}

// Appends the gathered points `indices` to `out` in `order`.
void append_points(const RenderPoints& from, const std::vector<std::uint32_t>& order,
                   RenderPoints& out) {
  for (const std::uint32_t k : order) {
    out.position.push_back(from.position[k]);
    out.normal.push_back(from.normal[k]);
    out.radii_m.push_back(from.radii_m[k]);
    out.major_axis.push_back(from.major_axis[k]);
    out.rgba.push_back(from.rgba[k]);
    out.intensity.push_back(from.intensity[k]);
    out.node.push_back(from.node[k]);
  }
}

// The tree's nodes into `model` (nodes, children, roots), then the root of
// the points no object owns; returns each node id's index (0: that root).
std::map<std::int64_t, std::size_t> link_tree(const std::vector<store::ObjectNode>& tree,
                                              RenderModel& model) {
  const std::map<std::int64_t, bool> shown = modeling::shown_nodes(tree);
  std::map<std::int64_t, std::size_t> index_of;
  for (const store::ObjectNode& n : tree) {
    index_of[n.id] = model.nodes.size();
    model.nodes.push_back({n, {}, {}, {}, shown.at(n.id)});
  }
  store::ObjectNode unassigned;
  unassigned.name = "unassigned";
  index_of[0] = model.nodes.size();
  model.nodes.push_back({unassigned, {}, {}, {}, true});
  for (std::size_t k = 0; k < model.nodes.size(); ++k) {
    const std::optional<std::int64_t> parent = model.nodes[k].node.parent;
    const auto found = parent ? index_of.find(*parent) : index_of.end();
    if (found == index_of.end()) {
      model.roots.push_back(k);
    } else {
      model.nodes[found->second].children.push_back(k);
    }
  }
  return index_of;
}

// One tile of `owner`: the points `part` (indices into `from`) appended to
// `out` in level-of-detail order, with their box and normal cone.
RenderTile make_tile(std::int64_t owner, const RenderPoints& from, std::vector<std::uint32_t>& part,
                     RenderPoints& out) {
  RenderTile tile;
  tile.node = owner;
  tile.first = static_cast<std::uint32_t>(out.size());
  tile.count = static_cast<std::uint32_t>(part.size());
  for (const std::uint32_t k : part) {
    tile.box.extend(from.position[k]);
    tile.max_radius_m = std::max(tile.max_radius_m, from.radii_m[k].maxCoeff());
  }
  tile.cone = normal_cone(from.normal, part);
  tile.level_ends = order_for_level_of_detail(from.position, part, tile.box);
  for (std::uint32_t& end : tile.level_ends) end += tile.first;
  tile.lod_cube_m = tile.box.sizes().maxCoeff();
  append_points(from, part, out);
  return tile;
}

// A group's box holds its descendants': children before parents.
void extend_group_boxes(RenderModel& model) {
  std::vector<std::size_t> post_order;
  std::vector<std::pair<std::size_t, bool>> stack;
  for (const std::size_t root : model.roots) stack.emplace_back(root, false);
  while (!stack.empty()) {
    const auto [at, expanded] = stack.back();
    stack.pop_back();
    if (expanded) {
      post_order.push_back(at);
      continue;
    }
    stack.emplace_back(at, true);
    for (const std::size_t child : model.nodes[at].children) stack.emplace_back(child, false);
  }
  for (const std::size_t at : post_order) {
    for (const std::size_t child : model.nodes[at].children) {
      if (!model.nodes[child].box.isEmpty()) model.nodes[at].box.extend(model.nodes[child].box);
    }
  }
}

}  // namespace

void RenderPoints::reserve(std::size_t n) {
  position.reserve(n);
  normal.reserve(n);
  radii_m.reserve(n);
  major_axis.reserve(n);
  rgba.reserve(n);
  intensity.reserve(n);
  node.reserve(n);
}

RenderModel build_render_model(const store::Project& project, const RenderModelSettings& settings) {
  const std::vector<store::StoredScanSummary> scans = project.scans();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  if (!scans.empty()) {
    const Eigen::Vector3d scanner = project.load_scan(scans.front().id).T_world_scan.translation();
    origin = scanner.array().round();
  }
  const std::vector<store::ObjectNode> tree = project.object_nodes();
  const std::map<std::int64_t, bool> shown = modeling::shown_nodes(tree);
  RenderModelCounts counts;
  RenderPoints points;
  const modeling::ColorPipeline colors(project.scan_color_corrections(),
                                       modeling::resolve_color_edits(tree));
  for (const store::StoredScanSummary& stored : scans)
    gather_scan(project, stored, settings, shown, colors, origin, points, counts);
  RenderModel model = assemble_render_model(std::move(points), origin, tree, settings.tiles);
  model.counts = counts;
  return model;
}

RenderModel assemble_render_model(RenderPoints points, const Eigen::Vector3d& origin,
                                  const std::vector<store::ObjectNode>& tree,
                                  const TileLimits& limits) {
  RenderModel model;
  model.origin = origin;
  model.counts.in_model = points.size();
  model.points.reserve(points.size());
  const std::map<std::int64_t, std::size_t> index_of = link_tree(tree, model);
  // Each node's points (a node not in the tree owns nothing), tiled.
  std::map<std::int64_t, std::vector<std::uint32_t>> by_node;
  for (std::uint32_t k = 0; k < points.size(); ++k) {
    if (!index_of.count(points.node[k])) points.node[k] = 0;
    by_node[points.node[k]].push_back(k);
  }
  for (auto& [owner, indices] : by_node) {
    RenderNode& node = model.nodes[index_of.at(owner)];
    for (std::vector<std::uint32_t>& part :
         split_into_tiles(points.position, std::move(indices), limits)) {
      node.tiles.push_back(model.tiles.size());
      model.tiles.push_back(make_tile(owner, points, part, model.points));
      node.box.extend(model.tiles.back().box);
    }
  }
  extend_group_boxes(model);
  return model;
}

}  // namespace scanbench::render
