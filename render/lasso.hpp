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

 private:
  std::vector<Eigen::Vector2f> vertices_;
  Eigen::AlignedBox2f bounds_;
};

// Where model point `p` lands on `view`'s picture (pixels from the top
// left); none when it lies behind the near plane.
std::optional<Eigen::Vector2f> project_to_picture(const RenderView& view, const Eigen::Vector3f& p);

// Where `box` (model frame) lands on the picture, as the bounds of its
// corners; none when a corner lies behind the near plane (the box may
// then cover any part of the picture).
std::optional<Eigen::AlignedBox2f> project_box(const RenderView& view,
                                               const Eigen::AlignedBox3f& box);

}  // namespace scanbench::render
