// Selecting in the 3D view (seed 002's selection in 3D): a lasso drawn on
// the picture selects the points whose centres it encloses, through every
// depth (a prism from the eye), in every scan at once. The store's renderer
// walks the nodes whose bounds may project into it (lod_renderer.hpp);
// this is the geometry, without OpenGL.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <span>
#include <vector>

#include "render/render_view.hpp"

namespace scanbench::render {

// A closed polygon on the picture (pixels from the top left), its edges
// from each vertex to the next and from the last back to the first.
class Lasso {
 public:
  // Fewer than three vertices enclose nothing.
  explicit Lasso(std::vector<Eigen::Vector2f> vertices);

  // Whether picture point `p` lies inside (even-odd rule).
  bool encloses(const Eigen::Vector2f& p) const;
  // Whether some of `box` (picture pixels) may lie inside: it meets the
  // polygon's bounds.
  bool may_meet(const Eigen::AlignedBox2f& box) const;
  bool empty() const { return vertices_.size() < 3; }
  const Eigen::AlignedBox2f& bounds() const { return bounds_; }

 private:
  std::vector<Eigen::Vector2f> vertices_;
  Eigen::AlignedBox2f bounds_;
};

// The nearest surface over a rectangle of the picture, from splats drawn
// as discs at their centre's depth: which of the points a lasso encloses
// a person sees in front, rather than what lies behind them.
class DepthRaster {
 public:
  // Pixels [x0, x1) × [y0, y1) of the picture; empty ones hold nothing.
  DepthRaster(int x0, int y0, int x1, int y1);

  // A splat centred at picture point `at`, `depth` [m] ahead of the eye,
  // covering a disc of `radius_px` (at least the pixel it falls in).
  void splat(const Eigen::Vector2f& at, float depth, float radius_px);
  // Whether a point at `at`, `depth` ahead lies on the nearest surface
  // there: no splat in front of it by more than `tolerance` [m]. Outside
  // the rectangle, true.
  bool in_front(const Eigen::Vector2f& at, float depth, float tolerance) const;

 private:
  int x0_, y0_, width_, height_;
  std::vector<float> nearest_;  // per pixel, +∞ where nothing was drawn
};

// How far ahead of the eye model point `p` lies along the view axis [m].
float view_depth(const RenderView& view, const Eigen::Vector3f& p);

// Where model point `p` lands on `view`'s picture (pixels from the top
// left); none when it lies behind the near plane.
std::optional<Eigen::Vector2f> project_to_picture(const RenderView& view, const Eigen::Vector3f& p);

// Where `box` (model frame) lands on the picture, as the bounds of its
// corners; none when a corner lies behind the near plane (the box may
// then cover any part of the picture).
std::optional<Eigen::AlignedBox2f> project_box(const RenderView& view,
                                               const Eigen::AlignedBox3f& box);

}  // namespace scanbench::render
