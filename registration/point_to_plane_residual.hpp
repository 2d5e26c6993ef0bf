// Point-to-plane residual of one correspondence under one unknown pose
// (pairwise ICP). Ceres is used from this file and the solvers only.
//
// A source sample s (source scan frame) matched to a target point p with unit
// normal n (target scan frame). With T_target_source = (R, t):
//
//   r = w · nᵀ (R s + t − p)
//
// the signed distance of the moved sample from the target's tangent plane.
// Minimising Σ ρ(r²) lets the surfaces slide along each other, which is why
// point-to-plane ICP converges in few iterations on the planar scenes of
// outdoor scans (Chen and Medioni 1992). w is 1 for an active correspondence
// and 0 for a sample without one, so that one Ceres problem is built per ICP
// run and only the correspondences change between solves.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace scanbench::registration {

// What a sample is matched to; rewritten by ICP before every solve.
struct PlaneMatch {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // target frame [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // target frame, unit
  double weight = 0.0;                               // 1 = active, 0 = none
};

class PointToPlaneResidual {
 public:
  // Both referents must outlive the Ceres problem.
  PointToPlaneResidual(const Eigen::Vector3d& source, const PlaneMatch& match)
      : source_(source), match_(match) {}

  template <typename T>
  bool operator()(const T* rotation_xyzw, const T* translation, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> R(rotation_xyzw);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(translation);
    const Eigen::Matrix<T, 3, 1> moved = R * source_.cast<T>() + t;
    residual[0] = T(match_.weight) * match_.normal.cast<T>().dot(moved - match_.point.cast<T>());
    return true;
  }

 private:
  const Eigen::Vector3d& source_;
  const PlaneMatch& match_;
};

}  // namespace scanbench::registration
