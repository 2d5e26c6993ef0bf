#include "acquisition/rigid_transform.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace scanbench::acquisition {

std::string rigid_transform_problem(const Eigen::Matrix4d& m) {
  if (!m.allFinite()) return "transform has a NaN or infinite entry";
  if (m.row(3).transpose() != Eigen::Vector4d(0, 0, 0, 1)) {
    return "transform is not affine (last row must be 0 0 0 1)";
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double orthogonality =
      (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > kRigidTolerance) {
    return "transform is not rigid (rotation block is not orthonormal: scale or shear)";
  }
  if (std::abs(r.determinant() - 1.0) > kRigidTolerance) {
    return "transform is not rigid (rotation block is a reflection)";
  }
  return {};
}

Eigen::Isometry3d to_isometry(const Eigen::Matrix4d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.topLeftCorner<3, 3>(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = svd.matrixU() * svd.matrixV().transpose();
  // Keep the exact input when it already is orthonormal to double precision, so
  // that file round trips reproduce the pose bit for bit.
  if ((pose.linear() - m.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff() < 1e-12) {
    pose.linear() = m.topLeftCorner<3, 3>();
  }
  pose.translation() = m.topRightCorner<3, 1>();
  return pose;
}

Eigen::Matrix4d matrix_from_row_major(const std::array<double, 16>& values) {
  return Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(values.data());
}

std::array<double, 16> row_major(const Eigen::Isometry3d& pose) {
  std::array<double, 16> values{};
  Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(values.data()) = pose.matrix();
  return values;
}

}  // namespace scanbench::acquisition
