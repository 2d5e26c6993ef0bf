#include "render/lasso.hpp"

namespace scanbench::render {

Lasso::Lasso(std::vector<Eigen::Vector2f> vertices) : vertices_(std::move(vertices)) {
  for (const Eigen::Vector2f& v : vertices_) bounds_.extend(v);
}

bool Lasso::encloses(const Eigen::Vector2f& p) const {
  if (empty() || !bounds_.contains(p)) return false;
  bool inside = false;
  for (std::size_t i = 0, j = vertices_.size() - 1; i < vertices_.size(); j = i++) {
    const Eigen::Vector2f& a = vertices_[i];
    const Eigen::Vector2f& b = vertices_[j];
    // Does the edge cross the horizontal ray from p to the right?
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const float x = a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
}

bool Lasso::may_meet(const Eigen::AlignedBox2f& box) const {
  return !empty() && bounds_.intersects(box);
}

std::optional<Eigen::Vector2f> project_to_picture(const RenderView& view,
                                                  const Eigen::Vector3f& p) {
  const Eigen::Vector4f eye = view.view * p.homogeneous();
  if (-eye.z() < view.near_m) return std::nullopt;
  const Eigen::Vector4f clip = view.projection * eye;
  const float x = clip.x() / clip.w(), y = clip.y() / clip.w();
  return Eigen::Vector2f(0.5f * (x + 1.0f) * static_cast<float>(view.width),
                         0.5f * (1.0f - y) * static_cast<float>(view.height));
}

std::optional<Eigen::AlignedBox2f> project_box(const RenderView& view,
                                               const Eigen::AlignedBox3f& box) {
  Eigen::AlignedBox2f out;
  for (int c = 0; c < 8; ++c) {
    const std::optional<Eigen::Vector2f> at =
        project_to_picture(view, box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)));
    if (!at) return std::nullopt;
    out.extend(*at);
  }
  return out;
}

}  // namespace scanbench::render
