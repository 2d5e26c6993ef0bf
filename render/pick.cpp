#include "render/pick.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scanbench::render {

Eigen::Vector3f pixel_ray(const RenderView& view, double x, double y) {
  // Normalised device coordinates, then back through the projection and the view.
  const float ndc_x = static_cast<float>(2.0 * x / view.width - 1.0);
  const float ndc_y = static_cast<float>(1.0 - 2.0 * y / view.height);
  const Eigen::Vector4f eye_dir =
      view.projection.inverse() * Eigen::Vector4f(ndc_x, ndc_y, 0.5f, 1.0f);
  const Eigen::Vector3f in_eye = (eye_dir.head<3>() / eye_dir.w()).normalized();
  const Eigen::Matrix3f eye_to_model = view.view.topLeftCorner<3, 3>().transpose();
  return (eye_to_model * in_eye).normalized();
}

std::optional<float> splat_hit(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                               const SplatShape& splat, float splat_scale, bool oriented,
                               float nearer_than) {
  const Eigen::Vector3f& p = splat.position;
  const Eigen::Vector3f to = p - origin;
  const float along = to.dot(direction);
  const float radius = splat.radii_m.maxCoeff() * splat_scale;
  // Cheap rejections first: behind the eye, farther than the best hit by
  // more than the splat's reach, or off the ray beyond it.
  if (along + radius <= 0.0f || along - radius >= nearer_than) return std::nullopt;
  if ((to - along * direction).squaredNorm() > radius * radius) return std::nullopt;
  const Eigen::Vector3f& normal = splat.normal;
  const bool has_normal = normal.squaredNorm() > 0.25f;
  if (has_normal && normal.dot(-to) < 0.0f) return std::nullopt;  // faces away
  // Where the ray meets the splat as the view draws it: the ellipse in the
  // plane of its normal, or a disk facing the eye (unoriented, no normal,
  // or seen edge on).
  bool in_plane = oriented && has_normal;
  Eigen::Vector3f n = in_plane ? normal : Eigen::Vector3f(-to.normalized());
  if (in_plane && std::abs(direction.dot(n)) < 0.05f) {
    in_plane = false;
    n = -to.normalized();
  }
  const float hit = to.dot(n) / direction.dot(n);
  if (!(hit > 0.0f) || hit >= nearer_than) return std::nullopt;
  const Eigen::Vector3f offset = origin + hit * direction - p;
  const Eigen::Vector2f r = splat.radii_m * splat_scale;
  const Eigen::Vector3f& major = splat.major_axis;
  float d2 = 0.0f;
  if (in_plane && major.squaredNorm() > 0.25f) {
    const Eigen::Vector2f e(offset.dot(n.cross(major)) / r.x(), offset.dot(major) / r.y());
    d2 = e.squaredNorm();
  } else {
    d2 = offset.squaredNorm() / (in_plane ? r.x() * r.x() : r.x() * r.y());
  }
  if (d2 > 1.0f) return std::nullopt;
  return hit;
}

std::optional<float> ray_box_entry(const Eigen::AlignedBox3f& box, const Eigen::Vector3f& origin,
                                   const Eigen::Vector3f& direction) {
  if (box.isEmpty()) return std::nullopt;
  float near = 0.0f, far = std::numeric_limits<float>::max();
  for (int a = 0; a < 3; ++a) {
    const float low = box.min()[a], high = box.max()[a];
    if (std::abs(direction[a]) < 1e-12f) {
      if (origin[a] < low || origin[a] > high) return std::nullopt;
      continue;
    }
    float t0 = (low - origin[a]) / direction[a], t1 = (high - origin[a]) / direction[a];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
    if (near > far) return std::nullopt;
  }
  return near;
}

}  // namespace scanbench::render
