// Point-to-plane costs for Ceres, many correspondences per residual block,
// with analytic Jacobians. Ceres is used from this file and the solvers only.
//
// A source sample s (source scan frame) matched to a target point p with unit
// normal n (target scan frame). For pairwise ICP, with T_target_source = (R, t):
//
//   r = nᵀ (R s + t − p)
//
// the signed distance of the moved sample from the target's tangent plane.
// Minimising Σ ρ(r²) lets the surfaces slide along each other, which is why
// point-to-plane ICP converges in few iterations on the planar scenes of
// outdoor scans (Chen and Medioni 1992). The global refinement reduces the
// same residuals to a quadratic per pair of scans (global_refinement.cpp).
//
// Rotations are unit quaternions in Eigen's (x, y, z, w) order, on
// ceres::EigenQuaternionManifold, so updates stay on SO(3) and no Euler-angle
// singularity exists; translations are plain 3-vectors [m].
//
// Why not one autodiff residual block per correspondence: with tens of
// thousands of matches per solve, the per-block bookkeeping and the dual
// numbers cost far more than the arithmetic. A block here holds up to
// kCorrespondencesPerBlock matches and evaluates them in one loop, and the
// blocks are evaluated in parallel by Ceres.
//
// Robust loss. Ceres applies a LossFunction to a whole block's squared norm,
// which would be wrong for a block of independent matches, so the Cauchy
// loss ρ(s) = b ln(1 + s/b), b = a², is applied per match inside the block:
// each residual is returned as sign(r) √ρ(r²), whose square is the robust
// cost of that match (the same objective Σ ρ(r²) as ceres::CauchyLoss), with
// its exact derivative.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "registration/association.hpp"

namespace scanbench::registration {

inline constexpr std::size_t kCorrespondencesPerBlock = 512;

// `matches` cut into consecutive blocks of at most kCorrespondencesPerBlock.
std::vector<std::span<const PlaneCorrespondence>> correspondence_blocks(
    std::span<const PlaneCorrespondence> matches);

// A match's robust residual and its derivative with respect to the plain
// point-to-plane distance r, for the Cauchy loss of scale a [m].
struct RobustResidual {
  double value = 0.0;  // sign(r) √ρ(r²)
  double slope = 1.0;  // d value / d r
};
RobustResidual cauchy_residual(double r, double scale_m);

// Pairwise ICP: parameter blocks (rotation 4, translation 3) of T_target_source.
class PointToPlaneCost final : public ceres::CostFunction {
 public:
  // `matches` must outlive the cost; at most kCorrespondencesPerBlock of them.
  PointToPlaneCost(std::span<const PlaneCorrespondence> matches, double loss_scale_m);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::span<const PlaneCorrespondence> matches_;
  double loss_scale_m_;
};

}  // namespace scanbench::registration
