#include "render/lasso.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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

DepthRaster::DepthRaster(int x0, int y0, int x1, int y1)
    : x0_(x0),
      y0_(y0),
      width_(std::max(0, x1 - x0)),
      height_(std::max(0, y1 - y0)),
      nearest_(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_),
               std::numeric_limits<float>::infinity()) {}

void DepthRaster::splat(const Eigen::Vector2f& at, float depth, float radius_px) {
  const float r = std::max(radius_px, 0.5f);
  const int xa = std::max(0, static_cast<int>(std::floor(at.x() - r)) - x0_);
  const int xb = std::min(width_ - 1, static_cast<int>(std::floor(at.x() + r)) - x0_);
  const int ya = std::max(0, static_cast<int>(std::floor(at.y() - r)) - y0_);
  const int yb = std::min(height_ - 1, static_cast<int>(std::floor(at.y() + r)) - y0_);
  const float r2 = r * r;
  for (int y = ya; y <= yb; ++y) {
    const float dy = static_cast<float>(y + y0_) + 0.5f - at.y();
    for (int x = xa; x <= xb; ++x) {
      const float dx = static_cast<float>(x + x0_) + 0.5f - at.x();
      // The pixel the centre falls in always counts, however small the disc.
      const bool own = std::abs(dx) <= 0.5f && std::abs(dy) <= 0.5f;
      if (!own && dx * dx + dy * dy > r2) continue;
      float& nearest = nearest_[static_cast<std::size_t>(y) * width_ + x];
      nearest = std::min(nearest, depth);
    }
  }
}

bool DepthRaster::in_front(const Eigen::Vector2f& at, float depth, float tolerance) const {
  const int x = static_cast<int>(std::floor(at.x())) - x0_;
  const int y = static_cast<int>(std::floor(at.y())) - y0_;
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return true;
  return depth <= nearest_[static_cast<std::size_t>(y) * width_ + x] + tolerance;
}

float view_depth(const RenderView& view, const Eigen::Vector3f& p) {
  return -(view.view * p.homogeneous()).z();
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
