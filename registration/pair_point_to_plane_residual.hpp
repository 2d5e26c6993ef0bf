// Point-to-plane residual of one correspondence between two scans whose
// poses are both unknown (global refinement over all overlapping pairs).
//
// Poses map scan frames into a common frame (the first scan's), T_i = (R_i, t_i).
// A sample s of scan a matched to point p with unit normal n of scan b:
//
//   r = w · (R_b n)ᵀ ((R_a s + t_a) − (R_b p + t_b))
//
// the distance of the sample from b's tangent plane, both in the common
// frame. Holding the first scan's pose constant fixes the gauge (the Ceres
// pose-graph example); every other pose moves, so an error around a loop is
// spread over all its scans instead of piling up at the last one.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace scanbench::registration {

class PairPointToPlaneResidual {
 public:
  // Scan frames [m]; `normal` unit.
  PairPointToPlaneResidual(const Eigen::Vector3d& sample, const Eigen::Vector3d& point,
                           const Eigen::Vector3d& normal)
      : sample_(sample), point_(point), normal_(normal) {}

  template <typename T>
  bool operator()(const T* rotation_a, const T* translation_a, const T* rotation_b,
                  const T* translation_b, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> R_a(rotation_a);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_a(translation_a);
    const Eigen::Map<const Eigen::Quaternion<T>> R_b(rotation_b);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_b(translation_b);
    const Eigen::Matrix<T, 3, 1> sample = R_a * sample_.cast<T>() + t_a;
    const Eigen::Matrix<T, 3, 1> point = R_b * point_.cast<T>() + t_b;
    residual[0] = (R_b * normal_.cast<T>()).dot(sample - point);
    return true;
  }

 private:
  Eigen::Vector3d sample_;
  Eigen::Vector3d point_;
  Eigen::Vector3d normal_;
};

}  // namespace scanbench::registration
