// Picking in the 3D view: the point a ray through a pixel meets first, as
// the view draws the model. What the view does not draw is not picked:
// hidden objects, points outside the clipping box or slice, and points
// facing away (the view culls them).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>

#include "render/frame_plan.hpp"
#include "render/render_model.hpp"
#include "render/render_view.hpp"

namespace scanbench::render {

struct Pick {
  std::size_t point = 0;     // into RenderModel::points
  float distance_m = 0.0f;   // from the ray's origin, along it, to where it meets the splat
  Eigen::Vector3f position;  // the point's own position, model frame
};

// The ray from the eye of `view` through pixel (x, y) (window pixels from
// the top left; pixel centres at +0.5) as a unit direction, model frame.
Eigen::Vector3f pixel_ray(const RenderView& view, double x, double y);

// A splat as the view draws it, model frame: zero normal: unknown (a disk
// facing the eye); zero major axis: round.
struct SplatShape {
  Eigen::Vector3f position;
  Eigen::Vector3f normal;
  Eigen::Vector3f major_axis;
  Eigen::Vector2f radii_m;  // (across, along the major axis)
};

// Where the ray from `origin` along unit `direction` meets `splat` (radii ×
// splat_scale; its ellipse in the plane of its normal when `oriented`,
// else a disk facing the eye): the distance along the ray, when it does at
// less than `nearer_than` and the splat faces the ray.
std::optional<float> splat_hit(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                               const SplatShape& splat, float splat_scale, bool oriented,
                               float nearer_than);

// Whether the ray meets `box` at a distance ≥ 0.
bool ray_meets_box(const Eigen::AlignedBox3f& box, const Eigen::Vector3f& origin,
                   const Eigen::Vector3f& direction);

// The point whose splat the ray from `origin` along unit `direction` meets
// first, the splat as the view draws it (splat_shaders.cpp): its ellipse
// (radii × splat_scale) in the plane of its normal when `oriented`, else a
// disk facing the eye. None when it meets none. Walks only the tiles whose
// box the ray crosses. (A sphere of the larger radius would let the long
// thin splats of distant ground catch rays that pass metres above them.)
std::optional<Pick> pick_point(const RenderModel& model, const Eigen::Vector3f& origin,
                               const Eigen::Vector3f& direction, const Clipping& clipping,
                               float splat_scale, bool oriented = true);

}  // namespace scanbench::render
