// The cost of one colour pair in colour harmonisation
// (color_harmonization.hpp), with its derivatives.
//
// A scan's correction maps its linear RGB colour c to
//   gain-offset  c' = g ∘ c + o            parameters (g₀ g₁ g₂ o₀ o₁ o₂)
//   matrix       c' = M c + o              parameters (M row-major, o)
// (matrix_parameter and offset_parameter below are that layout).
// A colour pair (the same surface point in scans a and b) has, per channel,
// the residual
//   r = s(c'_a) − s(c'_b),   s(v) = log(max(v, 0) + ε),   ε = 0.01.
// For c' ≫ ε this is log(c'_a / c'_b): a gain is a shift, so exposure and
// white balance differences are constant residuals that the gains remove
// exactly, and shrinking every colour of a scan towards one value (which
// would make scans that cannot agree agree with each other) does not pay.
// For c' ≲ ε it turns absolute (≈ (c'_a − c'_b) / ε), so dark noise does
// not dominate as it would under a true logarithm. The solver puts a Cauchy
// loss on it; its scale is a relative difference (0.05: about 5 %).
//
// Derivatives: s'(v) = 1 / (v + ε) for v > 0 and 0 below, and channel k of
// c' depends on the gain or matrix row of channel k and on offset k:
//   ∂r_k/∂g_k = s'(c'_k) c_k            (gain-offset, scan a; b: negated)
//   ∂r_k/∂M_kj = s'(c'_k) c_j           (matrix)
//   ∂r_k/∂o_k = s'(c'_k)
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "registration/color_harmonization.hpp"

namespace scanbench::registration::costs {

inline constexpr double kSoftLogEpsilon = 0.01;

// The parameter layout, written here only: where M(row, col) and o(row)
// sit in a scan's parameter vector p.
// The parameters of one scan's correction: 6 (gain-offset) or 12 (matrix).
constexpr int color_parameter_count(ColorModel model) {
  return model == ColorModel::kGainOffset ? 6 : 12;
}
// Index of M(row, col) in p; −1 where the model holds it at the identity's
// value (the gain-offset model's cross-talk).
constexpr int matrix_parameter(ColorModel model, int row, int col) {
  if (model == ColorModel::kGainOffset) return row == col ? row : -1;
  return 3 * row + col;
}
// Index of o(row) in p: the last three parameters.
constexpr int offset_parameter(ColorModel model, int row) {
  return color_parameter_count(model) - 3 + row;
}

template <ColorModel Model>
inline constexpr int kColorParameters = color_parameter_count(Model);

template <ColorModel Model>
using PairJacobian = Eigen::Matrix<double, 3, kColorParameters<Model>>;

// Channel k of c' for `rgb` under the parameters p.
template <ColorModel Model>
double corrected_channel(const double* p, const Eigen::Vector3f& rgb, int k) {
  double sum = 0.0;
  for (int j = 0; j < 3; ++j) {
    const int i = matrix_parameter(Model, k, j);
    if (i >= 0) sum += p[i] * double{rgb[j]};
  }
  return sum + p[offset_parameter(Model, k)];
}

inline double soft_log(double v) {
  return std::log(std::max(v, 0.0) + kSoftLogEpsilon);
}
inline double soft_log_slope(double v) {
  return v > 0.0 ? 1.0 / (v + kSoftLogEpsilon) : 0.0;
}

// Row k of a scan's Jacobian: `slope` × ∂c'_k/∂p.
template <ColorModel Model>
void set_jacobian_row(const Eigen::Vector3f& rgb, int k, double slope, PairJacobian<Model>& J) {
  for (int j = 0; j < 3; ++j) {
    const int i = matrix_parameter(Model, k, j);
    if (i >= 0) J(k, i) = slope * double{rgb[j]};
  }
  J(k, offset_parameter(Model, k)) = slope;
}

// The residual of the pair (rgb_a in scan a at parameters pa, rgb_b in b
// at pb), and where J_a and J_b are given, its Jacobians with respect to pa
// and pb.
template <ColorModel Model>
Eigen::Vector3d pair_residual(const double* pa, const double* pb, const Eigen::Vector3f& rgb_a,
                              const Eigen::Vector3f& rgb_b, PairJacobian<Model>* J_a = nullptr,
                              PairJacobian<Model>* J_b = nullptr) {
  Eigen::Vector3d r;
  if (J_a != nullptr) J_a->setZero();
  if (J_b != nullptr) J_b->setZero();
  for (int k = 0; k < 3; ++k) {
    const double ca = corrected_channel<Model>(pa, rgb_a, k);
    const double cb = corrected_channel<Model>(pb, rgb_b, k);
    r[k] = soft_log(ca) - soft_log(cb);
    if (J_a != nullptr) set_jacobian_row<Model>(rgb_a, k, soft_log_slope(ca), *J_a);
    if (J_b != nullptr) set_jacobian_row<Model>(rgb_b, k, -soft_log_slope(cb), *J_b);
  }
  return r;
}

// The Cauchy loss of a squared residual norm s at scale a:
// ρ(s) = a² log(1 + s / a²), and its slope ρ'(s) = 1 / (1 + s / a²), the
// weight of the pair's rows in the normal equations.
inline double cauchy_loss(double s, double scale) {
  const double b = scale * scale;
  return b * std::log1p(s / b);
}
inline double cauchy_weight(double s, double scale) {
  return 1.0 / (1.0 + s / (scale * scale));
}

}  // namespace scanbench::registration::costs
