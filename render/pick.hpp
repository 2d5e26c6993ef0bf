// Picking in the 3D view: where a ray through a pixel meets a splat as the
// view draws it. The store's renderer walks the nodes the ray crosses
// (lod_renderer.hpp); what the view does not draw is not picked: hidden
// objects, points outside the clipping box or slice, and points facing
// away.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "render/render_view.hpp"

namespace scanbench::render {

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
// less than `nearer_than` and the splat faces the ray. (A sphere of the
// larger radius would let the long thin splats of distant ground catch
// rays that pass metres above them.)
std::optional<float> splat_hit(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                               const SplatShape& splat, float splat_scale, bool oriented,
                               float nearer_than);

// Where the ray enters `box` (0 when it starts inside); none when it
// misses it.
std::optional<float> ray_box_entry(const Eigen::AlignedBox3f& box, const Eigen::Vector3f& origin,
                                   const Eigen::Vector3f& direction);

}  // namespace scanbench::render
