#include "registration/point_to_plane_costs.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>

namespace scanbench::registration {
namespace {

// The derivative of nᵀ (q ⊗ s), the rotated vector projected on n, with
// respect to the quaternion's four coordinates (x, y, z, w). Eigen rotates
// by q ⊗ s = s + 2w (v × s) + 2 v × (v × s), v = (x, y, z), hence
//   ∂/∂v = 2 (−w (n × s) + (n·v) s + (v·s) n − 2 (n·s) v)
//   ∂/∂w = 2 nᵀ (v × s)
// (the polynomial, differentiated as it stands; Ceres projects it onto the
// tangent space of the unit sphere).
Eigen::Vector4d rotated_projection_gradient(const Eigen::Quaterniond& q, const Eigen::Vector3d& s,
                                            const Eigen::Vector3d& n) {
  const Eigen::Vector3d v = q.vec();
  const double w = q.w();
  Eigen::Vector4d gradient;
  gradient.head<3>() = 2.0 * (-w * n.cross(s) + n.dot(v) * s + v.dot(s) * n - 2.0 * n.dot(s) * v);
  gradient[3] = 2.0 * n.dot(v.cross(s));
  return gradient;
}

// Writes one match's row of a rotation (4) and a translation (3) Jacobian
// block, when Ceres asks for that block.
void write_row(double* rotation_jacobian, double* translation_jacobian, std::size_t row,
               const Eigen::Vector4d& d_rotation, const Eigen::Vector3d& d_translation) {
  if (rotation_jacobian != nullptr) {
    Eigen::Map<Eigen::Vector4d>(rotation_jacobian + 4 * row) = d_rotation;
  }
  if (translation_jacobian != nullptr) {
    Eigen::Map<Eigen::Vector3d>(translation_jacobian + 3 * row) = d_translation;
  }
}

}  // namespace

std::vector<std::span<const PlaneCorrespondence>> correspondence_blocks(
    std::span<const PlaneCorrespondence> matches) {
  std::vector<std::span<const PlaneCorrespondence>> blocks;
  for (std::size_t begin = 0; begin < matches.size(); begin += kCorrespondencesPerBlock) {
    blocks.push_back(
        matches.subspan(begin, std::min(kCorrespondencesPerBlock, matches.size() - begin)));
  }
  return blocks;
}

RobustResidual cauchy_residual(double r, double scale_m) {
  // With x = r²/b: ρ(r²)/r² = ln(1 + x)/x (→ 1 as x → 0) and ρ'(r²) = 1/(1 + x).
  // value = r √(ρ/r²); d value/d r = ρ' |r| / √ρ = ρ' / √(ρ/r²).
  const double x = r * r / (scale_m * scale_m);
  const double ratio = x < 1e-8 ? 1.0 - 0.5 * x : std::log1p(x) / x;
  const double root = std::sqrt(ratio);
  return {r * root, 1.0 / ((1.0 + x) * root)};
}

PointToPlaneCost::PointToPlaneCost(std::span<const PlaneCorrespondence> matches,
                                   double loss_scale_m)
    : matches_(matches), loss_scale_m_(loss_scale_m) {
  assert(!matches.empty() && matches.size() <= kCorrespondencesPerBlock && loss_scale_m > 0.0);
  set_num_residuals(static_cast<int>(matches.size()));
  mutable_parameter_block_sizes()->assign({4, 3});
}

bool PointToPlaneCost::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> t(parameters[1]);
  const Eigen::Matrix3d R = q.toRotationMatrix();  // the same polynomial as q ⊗ s
  const bool derivatives = jacobians != nullptr;
  for (std::size_t i = 0; i < matches_.size(); ++i) {
    const PlaneCorrespondence& m = matches_[i];
    const RobustResidual robust =
        cauchy_residual(m.normal.dot(R * m.sample + t - m.point), loss_scale_m_);
    residuals[i] = robust.value;
    if (!derivatives) continue;
    write_row(jacobians[0], jacobians[1], i,
              robust.slope * rotated_projection_gradient(q, m.sample, m.normal),
              robust.slope * m.normal);
  }
  return true;
}

}  // namespace scanbench::registration
