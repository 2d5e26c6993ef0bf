// A camera in the render model's frame (world minus the model's origin), as
// OpenGL draws through it: the view and a reversed-Z projection.
//
// Reversed Z (near → depth 1, far → 0, GL_GREATER, a float depth buffer,
// clip control zero-to-one) spreads float precision evenly over distance,
// so a 0.5 m near plane and a 2 km far plane keep millimetres at the far end
// of a street, which the seed's w-buffer was there to fix.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "acquisition/camera_view.hpp"

namespace scanbench::render {

struct RenderView {
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();  // model → eye (x right, y up, −z ahead)
  Eigen::Matrix4f projection = Eigen::Matrix4f::Identity();
  Eigen::Vector3f eye = Eigen::Vector3f::Zero();  // the camera centre, model frame
  int width = 0;
  int height = 0;
  float focal_px = 1.0f;
  float near_m = 0.5f;
  float far_m = 2000.0f;

  // The frustum's six planes (left, right, bottom, top, near, far) in the
  // model frame, each (n, d) with n · p + d ≥ 0 inside.
  std::array<Eigen::Vector4f, 6> frustum_planes() const;
};

// The camera of a view file (acquisition/camera_view.hpp, OpenCV axes) for a
// model whose points are relative to `origin` [m, world]. Asserts
// 0 < near_m < far_m.
RenderView make_render_view(const acquisition::CameraView& camera, const Eigen::Vector3d& origin,
                            float near_m = 0.5f, float far_m = 2000.0f);

// The same camera with `pixels` more on every side (the principal point
// stays the centre): GL drops a point sprite whose centre leaves the clip
// volume, so splats straddling the picture's edge are drawn into a wider
// target and the picture is cut from its middle.
RenderView with_guard_band(const RenderView& view, int pixels);

// True when the box lies wholly outside one of the planes.
bool outside_frustum(const std::array<Eigen::Vector4f, 6>& planes, const Eigen::AlignedBox3f& box);

}  // namespace scanbench::render
