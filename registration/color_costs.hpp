// The costs of colour harmonisation (color_harmonization.hpp), templated
// for Ceres' automatic derivatives.
//
// A scan's correction maps its linear RGB colour c to
//   gain-offset  c' = g ∘ c + o            parameters (g₀ g₁ g₂ o₀ o₁ o₂)
//   matrix       c' = M c + o              parameters (M row-major, o)
// A colour pair (the same surface point in scans a and b) has, per channel,
// the residual
//   r = log(max(c'_a, 0) + ε) − log(max(c'_b, 0) + ε),   ε = 0.01.
// For c' ≫ ε this is log(c'_a / c'_b): a gain is a shift, so exposure and
// white balance differences are constant residuals that the gains remove
// exactly, and shrinking every colour of a scan towards one value (which
// would make scans that cannot agree agree with each other) does not pay.
// For c' ≲ ε it turns absolute (≈ (c'_a − c'_b) / ε), so dark noise does
// not dominate as it would under a true logarithm. The solver puts a Cauchy
// loss on it; its scale is a relative difference (0.05: about 5 %).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <vector>

#include "registration/color_harmonization.hpp"

namespace scanbench::registration::costs {

inline constexpr double kSoftLogEpsilon = 0.01;

template <ColorModel Model>
inline constexpr int kColorParameters = Model == ColorModel::kGainOffset ? 6 : 12;

// c' of `rgb` under the parameters p.
template <ColorModel Model, typename T>
void correct_color(const T* p, const Eigen::Vector3f& rgb, T* out) {
  for (int c = 0; c < 3; ++c) {
    if constexpr (Model == ColorModel::kGainOffset) {
      out[c] = p[c] * T(rgb[c]) + p[3 + c];
    } else {
      out[c] =
          p[3 * c] * T(rgb[0]) + p[3 * c + 1] * T(rgb[1]) + p[3 * c + 2] * T(rgb[2]) + p[9 + c];
    }
  }
}

// The residual of one colour pair (3 values) over both scans' parameters.
template <ColorModel Model>
struct ColorPairCost {
  Eigen::Vector3f rgb_a;
  Eigen::Vector3f rgb_b;
  template <typename T>
  bool operator()(const T* pa, const T* pb, T* residual) const {
    using std::log;
    T ca[3], cb[3];
    correct_color<Model>(pa, rgb_a, ca);
    correct_color<Model>(pb, rgb_b, cb);
    const T zero(0.0), soft(kSoftLogEpsilon);
    for (int c = 0; c < 3; ++c)
      residual[c] = log((ca[c] < zero ? zero : ca[c]) + soft) - log((cb[c] < zero ? zero : cb[c]) + soft);
    return true;
  }
};

// weight · (p − identity) for every parameter: a gentle tie of a scan's
// correction to "no change" where its pairs constrain it poorly.
struct IdentityPrior {
  std::vector<double> identity;
  double weight = 0.0;
  template <typename T>
  bool operator()(const T* const* parameters, T* residual) const {
    for (std::size_t k = 0; k < identity.size(); ++k)
      residual[k] = T(weight) * (parameters[0][k] - T(identity[k]));
    return true;
  }
};

}  // namespace scanbench::registration::costs
