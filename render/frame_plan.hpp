// What a frame draws (seed 004 §5, seed 000 §4): the render model's tiles
// culled through the object tree by the view frustum (a node's box outside
// it culls everything below the node) and by their normal cones (a tile all
// of whose points face away), thinned by level of detail where their points
// would be denser than the screen's pixels, cut to a point budget, and drawn
// front to back. The user's clipping box and slice cull whole nodes and
// tiles here, and single points in the shaders. No OpenGL here: the plan is plain data, tested on its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/render_model.hpp"
#include "render/render_view.hpp"

namespace scanbench::render {

// What the user limits the drawing to, in the model's frame (metres from
// its origin): a clipping box, and a section plane with a thickness (a
// slice). A point is drawn when it lies in both.
struct Clipping {
  Eigen::AlignedBox3f box;  // empty (the default): no box
  Eigen::Vector3f section_normal = Eigen::Vector3f::UnitZ();  // unit
  float section_offset = 0.0f;      // the plane: normal · p = offset
  float section_half_width = 0.0f;  // the slice's half thickness; 0: no plane

  bool active() const { return !box.isEmpty() || section_half_width > 0.0f; }
  bool keeps(const Eigen::Vector3f& p) const;
  // No point of `b` can be kept.
  bool excludes(const Eigen::AlignedBox3f& b) const;
};

struct CullSettings {
  Clipping clipping;
  bool frustum = true;
  bool backface = true;         // by tile normal cones (per point: the shaders)
  bool level_of_detail = true;  // thin tiles whose points are finer than lod_pixels
  float lod_pixels = 1.0f;      // [pixels] on screen
  std::size_t budget = 0;       // points per frame; 0: no budget
};

struct TileDraw {
  std::size_t tile = 0;       // into RenderModel::tiles
  std::uint32_t count = 0;    // the prefix of the tile's points drawn
  float min_radius_m = 0.0f;  // splat radius a thinned tile needs to stay closed
  float distance_m = 0.0f;    // eye to the tile's box
};

struct FramePlan {
  std::vector<TileDraw> draws;  // front to back
  std::size_t points = 0;       // in the model
  std::size_t submitted = 0;    // drawn
  std::size_t culled_clip = 0;  // outside the clipping box or the slice
  std::size_t culled_frustum = 0;
  std::size_t culled_backface = 0;
  std::size_t culled_budget = 0;  // thinned by level of detail or the budget
  std::size_t hidden = 0;         // of hidden objects
  std::size_t tiles_drawn = 0;
};

// The frame of `model` through `view` (the model's frame, metres): every
// tile of a shown node either drawn (a prefix of its points, never empty) or
// counted as culled; points of hidden nodes counted as hidden. An empty
// model gives an empty plan.
FramePlan plan_frame(const RenderModel& model, const RenderView& view,
                     const CullSettings& settings);

}  // namespace scanbench::render
