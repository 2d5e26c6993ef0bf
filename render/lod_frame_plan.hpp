// What a frame draws of a level-of-detail store (docs/lod.md; seed 000 §4,
// Potree's traversal): its nodes walked from the root, the largest on
// screen first, each culled by the frustum and the user's clipping, drawn
// as the prefix of its points whose cells are at most lod_pixels wide on
// screen, and refined by its children while its cells are wider. A node
// not in memory is asked for and its subtree waits (its ancestors, drawn,
// stand in for it). The point budget stops the walk: what is nearest and
// largest on screen is drawn first. No OpenGL here: the plan is plain data.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "modeling/lod/lod_store.hpp"
#include "render/clipping.hpp"
#include "render/render_view.hpp"

namespace scanbench::render {

// A store's nodes with their tree: what the walk needs of them.
struct LodHierarchy {
  lod::LodHeader header;
  std::vector<lod::LodNodeInfo> nodes;  // by locational code: a parent before its children
  // Each node's children, by octant; -1 where it has none.
  std::vector<std::array<std::int32_t, 8>> children;
  // The bounds of each node's points and its descendants', grown by their
  // largest splat radius [m from the origin]; empty when it holds none.
  std::vector<Eigen::AlignedBox3f> reach;
  // The points each node and its descendants hold (a node's points_below
  // also counts those of its region its ancestors hold).
  std::vector<std::uint64_t> held;

  // The hierarchy of `store`'s nodes.
  static LodHierarchy of(const lod::LodStore& store);
  // The same from a store's header and nodes (tests).
  static LodHierarchy of(const lod::LodHeader& header, std::vector<lod::LodNodeInfo> nodes);
};

struct LodPlanSettings {
  Clipping clipping;
  bool frustum = true;
  float lod_pixels = 1.0f;  // [pixels] the widest a drawn cell may be on screen
  std::size_t budget = 0;   // points per frame; 0: no budget
};

struct LodNodeDraw {
  std::size_t node = 0;     // into LodHierarchy::nodes
  std::uint32_t count = 0;  // the prefix of its points drawn (whole levels)
  float distance_m = 0.0f;  // eye to its bounds
  // The cell of the deepest level drawn [m]: where none of its children is
  // drawn, its splats must reach that far for the surface to stay closed.
  float cell_m = 0.0f;
  std::uint8_t children_drawn = 0;  // bit k: the child in octant k is drawn
};

struct LodFramePlan {
  std::vector<LodNodeDraw> draws;  // front to back
  // Nodes the frame would draw but are not in memory, the most wanted first.
  std::vector<std::size_t> wanted;
  std::size_t points = 0;             // in the store
  std::size_t submitted = 0;          // drawn
  std::size_t culled_frustum = 0;     // in nodes outside the frustum
  std::size_t culled_clip = 0;        // in nodes outside the clipping
  std::size_t stopped_by_budget = 0;  // in nodes the budget left out
};

// The frame of the store `hierarchy` describes through `view`; `loaded(k)`
// says whether node k's points are in memory. An empty store gives an
// empty plan.
LodFramePlan plan_lod_frame(const LodHierarchy& hierarchy, const RenderView& view,
                            const LodPlanSettings& settings,
                            const std::function<bool(std::size_t)>& loaded);

}  // namespace scanbench::render
