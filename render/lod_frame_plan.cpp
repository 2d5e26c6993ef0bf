#include "render/lod_frame_plan.hpp"

#include <algorithm>
#include <cmath>
#include <queue>
#include <unordered_map>

namespace scanbench::render {
namespace {

// Each node's cell at its grid's finest level [m].
float finest_cell_m(const lod::LodHeader& header, const lod::NodeKey& key) {
  return static_cast<float>(static_cast<double>(header.cube.node_edge(key.depth)) * lod::kQuantumM /
                            static_cast<double>(1u << lod::kCellBits));
}

// How large a node looks from the eye: its bounds' radius over their
// distance (a node around the eye comes first).
float screen_weight(const Eigen::AlignedBox3f& box, const Eigen::Vector3f& eye) {
  const float radius = 0.5f * box.sizes().norm();
  const float distance = (box.center() - eye).norm();
  return distance <= radius ? std::numeric_limits<float>::max() : radius / distance;
}

}  // namespace

LodHierarchy LodHierarchy::of(const lod::LodStore& store) {
  return of(store.header(), store.nodes());
}

LodHierarchy LodHierarchy::of(const lod::LodHeader& header, std::vector<lod::LodNodeInfo> nodes) {
  LodHierarchy h;
  h.header = header;
  h.nodes = std::move(nodes);
  std::sort(h.nodes.begin(), h.nodes.end(),
            [](const lod::LodNodeInfo& a, const lod::LodNodeInfo& b) {
              return a.key.code() < b.key.code();
            });
  std::unordered_map<std::uint64_t, std::size_t> index_of;
  for (std::size_t k = 0; k < h.nodes.size(); ++k) index_of.emplace(h.nodes[k].key.code(), k);
  h.children.assign(h.nodes.size(), {-1, -1, -1, -1, -1, -1, -1, -1});
  h.reach.assign(h.nodes.size(), Eigen::AlignedBox3f());
  h.held.assign(h.nodes.size(), 0);
  // Children after parents in code order: backwards, each reach is whole
  // before its parent takes it in.
  for (std::size_t k = h.nodes.size(); k-- > 0;) {
    const lod::LodNodeInfo& node = h.nodes[k];
    h.held[k] += node.points;
    if (!node.bounds.isEmpty()) {
      const Eigen::Vector3f grow = Eigen::Vector3f::Constant(node.max_radius_m);
      h.reach[k].extend(Eigen::AlignedBox3f(node.bounds.min() - grow, node.bounds.max() + grow));
    }
    if (node.key.depth == 0) continue;
    const auto parent = index_of.find(node.key.parent().code());
    if (parent == index_of.end()) continue;  // an orphan: not reached from the root
    h.children[parent->second][static_cast<std::size_t>(node.key.octant())] =
        static_cast<std::int32_t>(k);
    if (!h.reach[k].isEmpty()) h.reach[parent->second].extend(h.reach[k]);
    h.held[parent->second] += h.held[k];
  }
  return h;
}

LodFramePlan plan_lod_frame(const LodHierarchy& hierarchy, const RenderView& view,
                            const LodPlanSettings& settings,
                            const std::function<bool(std::size_t)>& loaded) {
  LodFramePlan plan;
  plan.points = static_cast<std::size_t>(hierarchy.header.points);
  if (hierarchy.nodes.empty() || hierarchy.nodes.front().key.depth != 0) return plan;
  const std::array<Eigen::Vector4f, 6> planes = view.frustum_planes();
  std::priority_queue<std::pair<float, std::size_t>> queue;
  queue.emplace(std::numeric_limits<float>::max(), 0);
  std::vector<std::int32_t> draw_of(hierarchy.nodes.size(), -1);
  while (!queue.empty()) {
    const std::size_t k = queue.top().second;
    queue.pop();
    const lod::LodNodeInfo& node = hierarchy.nodes[k];
    const Eigen::AlignedBox3f& box = hierarchy.reach[k];
    const auto below = static_cast<std::size_t>(hierarchy.held[k]);
    if (box.isEmpty()) continue;
    if (settings.clipping.excludes(box)) {
      plan.culled_clip += below;
      continue;
    }
    if (settings.frustum && outside_frustum(planes, box)) {
      plan.culled_frustum += below;
      continue;
    }
    if (!loaded(k)) {
      plan.wanted.push_back(k);
      continue;
    }
    if (settings.budget > 0 && plan.submitted + node.points > settings.budget) {
      plan.stopped_by_budget += below;
      continue;
    }
    const float distance = std::sqrt(box.squaredExteriorDistance(view.eye));
    const float finest = finest_cell_m(hierarchy.header, node.key);
    // The coarsest level whose cells are at most lod_pixels on screen.
    int level = lod::kNodeLevels - 1;
    for (int l = 0; l <= lod::kCellBits; ++l) {
      const float cell = finest * static_cast<float>(1u << (lod::kCellBits - l));
      if (distance > 0.0f && cell * view.focal_px / distance <= settings.lod_pixels) {
        level = l;
        break;
      }
    }
    LodNodeDraw draw;
    draw.node = k;
    draw.count = node.level_ends[static_cast<std::size_t>(level)];
    draw.distance_m = distance;
    draw.cell_m =
        finest * static_cast<float>(1u << (lod::kCellBits - std::min(level, lod::kCellBits)));
    if (draw.count > 0) {
      draw_of[k] = static_cast<std::int32_t>(plan.draws.size());
      plan.draws.push_back(draw);
      plan.submitted += draw.count;
    }
    // Even its finest cells are too wide: its children refine it.
    if (level < lod::kNodeLevels - 1) continue;
    for (const std::int32_t child : hierarchy.children[k]) {
      if (child < 0) continue;
      queue.emplace(screen_weight(hierarchy.reach[static_cast<std::size_t>(child)], view.eye),
                    static_cast<std::size_t>(child));
    }
  }
  for (LodNodeDraw& draw : plan.draws) {
    for (int octant = 0; octant < 8; ++octant) {
      const std::int32_t child = hierarchy.children[draw.node][static_cast<std::size_t>(octant)];
      if (child >= 0 && draw_of[static_cast<std::size_t>(child)] >= 0)
        draw.children_drawn |= 1u << octant;
    }
  }
  std::stable_sort(
      plan.draws.begin(), plan.draws.end(),
      [](const LodNodeDraw& a, const LodNodeDraw& b) { return a.distance_m < b.distance_m; });
  return plan;
}

}  // namespace scanbench::render
