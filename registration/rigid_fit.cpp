#include "registration/rigid_fit.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace scanbench::registration {
namespace {

// The spread of the source points must span a plane: with all points on a
// line the rotation about it is free. Relative to the largest spread, so the
// test does not depend on units or scene size.
constexpr double kMinRelativeSpread = 1e-10;

bool spans_a_plane(const Eigen::Matrix3d& scatter) {
  const Eigen::Vector3d eigenvalues = scatter.selfadjointView<Eigen::Lower>().eigenvalues();
  return eigenvalues(2) > 0.0 && eigenvalues(1) > kMinRelativeSpread * eigenvalues(2);
}

}  // namespace

RigidFitResult fit_rigid(std::span<const PointPair> pairs) {
  RigidFitResult result;
  result.pairs = pairs.size();
  if (pairs.size() < 3) return result;

  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_mean = Eigen::Vector3d::Zero();
  for (const PointPair& pair : pairs) {
    source_mean += pair.source;
    target_mean += pair.target;
  }
  source_mean /= static_cast<double>(pairs.size());
  target_mean /= static_cast<double>(pairs.size());

  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();    // Σ (t − t̄)(s − s̄)ᵀ
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();  // Σ (s − s̄)(s − s̄)ᵀ
  for (const PointPair& pair : pairs) {
    const Eigen::Vector3d s = pair.source - source_mean;
    cross += (pair.target - target_mean) * s.transpose();
    scatter += s * s.transpose();
  }
  if (!spans_a_plane(scatter)) return result;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d signs(1.0, 1.0, 1.0);
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) signs(2) = -1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();

  result.T_target_source.linear() = rotation;
  result.T_target_source.translation() = target_mean - rotation * source_mean;
  double sum_squared = 0.0;
  for (const PointPair& pair : pairs) {
    const double residual = (result.T_target_source * pair.source - pair.target).norm();
    sum_squared += residual * residual;
    result.max_residual_m = std::max(result.max_residual_m, residual);
  }
  result.rms_m = std::sqrt(sum_squared / static_cast<double>(pairs.size()));
  result.valid = true;
  return result;
}

}  // namespace scanbench::registration
