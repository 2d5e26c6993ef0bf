#include "render/frame_plan.hpp"

#include <algorithm>
#include <cmath>

namespace scanbench::render {

namespace {

float distance_to_box(const Eigen::AlignedBox3f& box, const Eigen::Vector3f& eye) {
  return std::sqrt(box.squaredExteriorDistance(eye));
}

// The tile's points of levels ≤ the first whose cells are at most
// `pixels` wide on screen at `distance` (all of them when none is).
std::uint32_t level_of_detail_count(const RenderTile& tile, float distance, float focal_px,
                                    float pixels) {
  if (distance <= 0.0f) return tile.count;
  for (std::size_t level = 0; level < tile.level_ends.size(); ++level) {
    const float cell = tile.lod_cube_m / static_cast<float>(1u << std::min<std::size_t>(level, 30));
    if (cell * focal_px / distance <= pixels) return tile.level_ends[level] - tile.first;
  }
  return tile.count;
}

// The splat radius that keeps a prefix of `count` points closed: the cell of
// the deepest level the prefix holds whole (0 when it holds them all).
float min_radius_for(const RenderTile& tile, std::uint32_t count) {
  if (count >= tile.count) return 0.0f;
  float cell = tile.lod_cube_m;
  for (std::size_t level = 0; level < tile.level_ends.size(); ++level) {
    if (tile.level_ends[level] - tile.first > count) break;
    cell = tile.lod_cube_m / static_cast<float>(1u << std::min<std::size_t>(level, 30));
  }
  return cell;
}

struct Walk {
  const RenderModel& model;
  const RenderView& view;
  const CullSettings& settings;
  std::array<Eigen::Vector4f, 6> planes;
  FramePlan plan;

  std::size_t points_below(std::size_t node) const {
    std::size_t n = 0;
    for (const std::size_t t : model.nodes[node].tiles) n += model.tiles[t].count;
    for (const std::size_t child : model.nodes[node].children) n += points_below(child);
    return n;
  }

  void visit(std::size_t index) {
    const RenderNode& node = model.nodes[index];
    if (!node.shown) {
      plan.hidden += points_below(index);
      return;
    }
    if (settings.clipping.excludes(node.box)) {
      plan.culled_clip += points_below(index);
      return;
    }
    if (settings.frustum && !node.box.isEmpty() && outside_frustum(planes, node.box)) {
      plan.culled_frustum += points_below(index);
      return;
    }
    for (const std::size_t t : node.tiles) visit_tile(t);
    for (const std::size_t child : node.children) visit(child);
  }

  void visit_tile(std::size_t t) {
    const RenderTile& tile = model.tiles[t];
    if (settings.clipping.excludes(tile.box)) {
      plan.culled_clip += tile.count;
      return;
    }
    if (settings.frustum && outside_frustum(planes, tile.box)) {
      plan.culled_frustum += tile.count;
      return;
    }
    if (settings.backface && faces_away(tile.cone, tile.box, view.eye)) {
      plan.culled_backface += tile.count;
      return;
    }
    TileDraw draw{t, tile.count, 0.0f, distance_to_box(tile.box, view.eye)};
    if (settings.level_of_detail) {
      draw.count = level_of_detail_count(tile, draw.distance_m, view.focal_px, settings.lod_pixels);
    }
    plan.draws.push_back(draw);
  }
};

}  // namespace

bool Clipping::keeps(const Eigen::Vector3f& p) const {
  if (!box.isEmpty() && !box.contains(p)) return false;
  return section_half_width <= 0.0f ||
         std::abs(section_normal.dot(p) - section_offset) <= section_half_width;
}

bool Clipping::excludes(const Eigen::AlignedBox3f& b) const {
  if (b.isEmpty()) return false;
  if (!box.isEmpty() && !box.intersects(b)) return true;
  if (section_half_width <= 0.0f) return false;
  // The box's extent along the normal against the slab.
  const float centre = section_normal.dot(b.center()) - section_offset;
  const float reach = 0.5f * section_normal.cwiseAbs().dot(b.sizes());
  return centre - reach > section_half_width || centre + reach < -section_half_width;
}

FramePlan plan_frame(const RenderModel& model, const RenderView& view,
                     const CullSettings& settings) {
  Walk walk{model, view, settings, view.frustum_planes(), {}};
  walk.plan.points = model.points.size();
  for (const std::size_t root : model.roots) walk.visit(root);
  FramePlan plan = std::move(walk.plan);
  std::size_t wanted = 0;
  for (const TileDraw& draw : plan.draws) wanted += draw.count;
  // Over budget: every tile keeps the same share, so near and far thin alike.
  const double share = settings.budget > 0 && wanted > settings.budget
                           ? static_cast<double>(settings.budget) / static_cast<double>(wanted)
                           : 1.0;
  std::size_t visible = 0;
  for (TileDraw& draw : plan.draws) {
    const RenderTile& tile = model.tiles[draw.tile];
    visible += tile.count;
    draw.count = std::max<std::uint32_t>(
        1, static_cast<std::uint32_t>(std::floor(share * static_cast<double>(draw.count))));
    draw.min_radius_m = min_radius_for(tile, draw.count);
    plan.submitted += draw.count;
  }
  plan.culled_budget = visible - plan.submitted;
  plan.tiles_drawn = plan.draws.size();
  std::stable_sort(plan.draws.begin(), plan.draws.end(), [](const TileDraw& a, const TileDraw& b) {
    return a.distance_m < b.distance_m;
  });
  return plan;
}

}  // namespace scanbench::render
