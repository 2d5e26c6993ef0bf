#include "modeling/lod/splat_shape.hpp"

#include <algorithm>
#include <cmath>
#include <variant>

namespace scanbench::lod {

ScanSplats::ScanSplats(const acquisition::Scan& description, float max_stretch)
    : description_(acquisition::without_arrays(description)),
      max_stretch_(max_stretch),
      rotation_(description.T_world_scan.linear().cast<float>()),
      up_(description.T_world_scan.linear().transpose().col(2).cast<float>()),
      wraps_(acquisition::wraps_around(description)) {
  if (description.is_spherical()) spherical_.emplace(description);
  if (const auto* a = std::get_if<acquisition::SphericalAngles>(&description_.angles)) {
    half_cell_rad_.resize(static_cast<std::size_t>(description.rows));
    for (int row = 0; row < description.rows; ++row) {
      const double across =
          a->azimuth_step_rad * std::cos(a->elevation_start_rad + row * a->elevation_step_rad);
      half_cell_rad_[static_cast<std::size_t>(row)] =
          static_cast<float>(0.5 * std::hypot(across, a->elevation_step_rad));
    }
  }
}

Eigen::Vector3d ScanSplats::direction(const acquisition::Scan& held, int first_row, int row,
                                      int col) const {
  if (spherical_) return spherical_->precise(first_row + row, col);
  return acquisition::direction_precise(held, row, col, first_row);
}

// How far the pixel's samples reach along its surface, when the pixel lies
// inside ground its scan sampled; none elsewhere. Ground (facing up within
// 30°, below the scanner) is what a terrestrial scanner sees at grazing
// incidence over tens of metres, its rows far apart. Elsewhere a beam that
// grazes a surface is mostly on a silhouette, and the normals of small
// objects seen edge on are too rough for 1 / cos θ. Each neighbour must be a
// return within `reach` [m] and within 20° of the tangent plane, or a
// dropout (far grazing ground loses returns; beyond ground there is no sky);
// at least two must be returns.
std::optional<float> ScanSplats::sample_reach(const acquisition::Scan& held, int first_row,
                                              const Eigen::Vector3f& n, int row, int col,
                                              float reach) const {
  const auto point = [&](int r, int c) {
    return (held.range_m[held.index(r, c)] * direction(held, first_row, r, c).cast<float>()).eval();
  };
  const Eigen::Vector3f p = point(row, col);
  if (n.dot(up_) < 0.866f || p.dot(up_) >= 0.0f) return std::nullopt;  // not ground seen from above
  constexpr int kSteps[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  int returns = 0;
  float widest = 0.0f;
  for (const auto& step : kSteps) {
    const int r = row + step[0];
    int c = col + step[1];
    if (c < 0 || c >= held.columns) {
      if (!wraps_) return std::nullopt;
      c = (c + held.columns) % held.columns;
    }
    // Rows beyond the held ones are beyond the grid (the band's context).
    if (r < 0 || r >= held.rows) return std::nullopt;
    if (!held.valid[held.index(r, c)]) continue;  // far grazing ground loses returns
    ++returns;
    const Eigen::Vector3f step_to = point(r, c) - p;
    const float distance = step_to.norm();
    // Too far, or off the tangent plane by more than 20°: another surface.
    if (distance > reach || std::abs(n.dot(step_to)) > 0.35f * distance) return std::nullopt;
    widest = std::max(widest, distance);
  }
  if (returns < 2) return std::nullopt;
  return widest;
}

Splat ScanSplats::splat(const acquisition::Scan& held, int first_row,
                        const acquisition::ScanGeometry& geometry, std::size_t g, int row,
                        int col) const {
  Splat s;
  const float footprint = geometry.footprint_m[g];
  s.radii_m = Eigen::Vector2f(footprint, footprint);
  if (!geometry.has_normal(g)) return s;
  const Eigen::Vector3f n = geometry.normal[g];
  s.normal = rotation_ * n;
  if (description_.is_scattered()) return s;  // its footprint is a spacing on the surface
  const Eigen::Vector3f beam =
      direction(held, first_row, row, col).cast<float>();  // scanner → point
  constexpr float kEdgeOnStretch = 4.0f;                   // the geometry stage's footprint limit
  float cos_incidence = std::clamp(std::abs(n.dot(beam)), 1.0f / max_stretch_, 1.0f);
  const float head_on = half_cell_rad_.empty()
                            ? footprint * cos_incidence
                            : held.range_m[held.index(row, col)] *
                                  half_cell_rad_[static_cast<std::size_t>(first_row + row)];
  if (cos_incidence < 1.0f / kEdgeOnStretch) {
    const std::optional<float> along =
        sample_reach(held, first_row, n, row, col, 2.0f * head_on / cos_incidence);
    const float limit = along ? std::max(*along / head_on, kEdgeOnStretch) : kEdgeOnStretch;
    cos_incidence = std::max(cos_incidence, 1.0f / limit);
  }
  const Eigen::Vector3f slope = beam - n.dot(beam) * n;  // the beam's trace on the surface
  s.radii_m = Eigen::Vector2f(head_on, head_on);
  if (slope.norm() < 1e-3f) return s;  // head on: round
  s.radii_m.y() = head_on / cos_incidence;
  s.major_axis = rotation_ * slope.normalized();
  return s;
}

}  // namespace scanbench::lod
