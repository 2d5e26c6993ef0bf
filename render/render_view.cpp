#include "render/render_view.hpp"

#include <cassert>

namespace scanbench::render {

RenderView make_render_view(const acquisition::CameraView& camera, const Eigen::Vector3d& origin,
                            float near_m, float far_m) {
  assert(near_m > 0.0f && near_m < far_m);
  RenderView out;
  out.width = camera.width;
  out.height = camera.height;
  out.focal_px = static_cast<float>(camera.focal_px());
  out.near_m = near_m;
  out.far_m = far_m;
  // Model → OpenCV camera in double (the pose may sit at 10^6 m), then
  // OpenCV's axes (y down, z ahead) to OpenGL's (y up, z behind).
  const Eigen::Isometry3d camera_model =
      camera.T_world_camera.inverse() * Eigen::Translation3d(origin);
  const Eigen::Matrix4d flip = Eigen::Vector4d(1.0, -1.0, -1.0, 1.0).asDiagonal();
  out.view = (flip * camera_model.matrix()).cast<float>();
  out.eye = (camera.T_world_camera.translation() - origin).cast<float>();
  const float a = near_m / (far_m - near_m);
  const float b = far_m * near_m / (far_m - near_m);
  out.projection.setZero();
  out.projection(0, 0) = 2.0f * out.focal_px / static_cast<float>(camera.width);
  out.projection(1, 1) = 2.0f * out.focal_px / static_cast<float>(camera.height);
  out.projection(2, 2) = a;  // z_eye = −near → depth 1, z_eye = −far → depth 0
  out.projection(2, 3) = b;
  out.projection(3, 2) = -1.0f;
  return out;
}

RenderView with_guard_band(const RenderView& view, int pixels) {
  RenderView wider = view;
  wider.width += 2 * pixels;
  wider.height += 2 * pixels;
  wider.projection(0, 0) = 2.0f * view.focal_px / static_cast<float>(wider.width);
  wider.projection(1, 1) = 2.0f * view.focal_px / static_cast<float>(wider.height);
  return wider;
}

std::array<Eigen::Vector4f, 6> RenderView::frustum_planes() const {
  // Rows of the clip matrix: −w ≤ x, y ≤ w and 0 ≤ z ≤ w (zero-to-one depth).
  const Eigen::Matrix4f clip = projection * view;
  const Eigen::RowVector4f x = clip.row(0), y = clip.row(1), z = clip.row(2), w = clip.row(3);
  std::array<Eigen::Vector4f, 6> planes = {(w + x).transpose(), (w - x).transpose(),
                                           (w + y).transpose(), (w - y).transpose(),
                                           (w - z).transpose(), z.transpose()};
  for (Eigen::Vector4f& plane : planes) plane /= plane.head<3>().norm();
  return planes;
}

bool outside_frustum(const std::array<Eigen::Vector4f, 6>& planes, const Eigen::AlignedBox3f& box) {
  for (const Eigen::Vector4f& plane : planes) {
    // The box's corner furthest along the plane's normal.
    const Eigen::Vector3f far_corner =
        (plane.head<3>().array() >= 0.0f).select(box.max(), box.min());
    if (plane.head<3>().dot(far_corner) + plane.w() < 0.0f) return true;
  }
  return false;
}

}  // namespace scanbench::render
