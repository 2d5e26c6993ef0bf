#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "registration/point_to_plane_costs.hpp"

namespace scanbench::registration {
namespace {

std::vector<PlaneCorrespondence> random_matches(std::size_t count, std::mt19937& random) {
  std::uniform_real_distribution<double> coordinate(-20.0, 20.0);
  std::vector<PlaneCorrespondence> matches;
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d sample(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d point(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d normal =
        Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)).normalized();
    // Points near their plane, as after association, and a few far off.
    matches.push_back({sample,
                       sample + normal * (i % 7 == 0 ? 1.5 : 0.01 * coordinate(random)) +
                           normal.unitOrthogonal() * coordinate(random),
                       normal});
  }
  return matches;
}

Eigen::Quaterniond random_rotation(std::mt19937& random) {
  std::normal_distribution<double> gauss;
  return Eigen::Quaterniond(gauss(random), gauss(random), gauss(random), gauss(random))
      .normalized();
}

// Analytic Jacobians against central differences in the tangent space of
// each parameter block (through the quaternion manifold's Plus for
// rotations, plain addition for translations).
void expect_gradients_match(const ceres::CostFunction& cost,
                            const std::vector<const ceres::Manifold*>& manifolds,
                            const std::vector<const double*>& parameters) {
  const std::vector<int>& sizes = cost.parameter_block_sizes();
  const auto rows = static_cast<std::size_t>(cost.num_residuals());
  std::vector<std::vector<double>> jacobians;
  std::vector<double*> jacobian_pointers;
  for (int size : sizes) jacobians.emplace_back(rows * static_cast<std::size_t>(size));
  for (auto& j : jacobians) jacobian_pointers.push_back(j.data());
  std::vector<double> residuals(rows);
  ASSERT_TRUE(cost.Evaluate(parameters.data(), residuals.data(), jacobian_pointers.data()));
  constexpr double kStep = 1e-6;
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    const int ambient = sizes[b];
    const int tangent = manifolds[b] != nullptr ? manifolds[b]->TangentSize() : ambient;
    std::vector<double> plus_jacobian(static_cast<std::size_t>(ambient * tangent), 0.0);
    if (manifolds[b] != nullptr) {
      manifolds[b]->PlusJacobian(parameters[b], plus_jacobian.data());
    } else {
      for (int k = 0; k < ambient; ++k)
        plus_jacobian[static_cast<std::size_t>(k * tangent + k)] = 1.0;
    }
    for (int k = 0; k < tangent; ++k) {
      std::vector<std::vector<double>> moved(
          2, std::vector<double>(static_cast<std::size_t>(ambient)));
      std::vector<std::vector<double>> moved_residuals(2, std::vector<double>(rows));
      for (int side = 0; side < 2; ++side) {
        std::vector<double> delta(static_cast<std::size_t>(tangent), 0.0);
        delta[static_cast<std::size_t>(k)] = side == 0 ? kStep : -kStep;
        if (manifolds[b] != nullptr) {
          manifolds[b]->Plus(parameters[b], delta.data(), moved[side].data());
        } else {
          for (int i = 0; i < ambient; ++i) moved[side][i] = parameters[b][i] + delta[i];
        }
        std::vector<const double*> moved_parameters = parameters;
        moved_parameters[b] = moved[side].data();
        ASSERT_TRUE(cost.Evaluate(moved_parameters.data(), moved_residuals[side].data(), nullptr));
      }
      for (std::size_t row = 0; row < rows; ++row) {
        double analytic = 0.0;
        for (int i = 0; i < ambient; ++i) {
          analytic += jacobians[b][row * ambient + i] * plus_jacobian[i * tangent + k];
        }
        const double numeric = (moved_residuals[0][row] - moved_residuals[1][row]) / (2.0 * kStep);
        EXPECT_NEAR(analytic, numeric, 1e-6 * (1.0 + std::abs(numeric)))
            << "block " << b << ", tangent " << k << ", row " << row;
      }
    }
  }
}

TEST(PointToPlaneCosts, CauchyResidualSquaresToTheCauchyLossAndHasItsSlope) {
  for (const double r : {-3.0, -0.05, -1e-6, 0.0, 2e-5, 0.02, 0.4, 10.0}) {
    const double a = 0.02;
    const RobustResidual robust = cauchy_residual(r, a);
    EXPECT_NEAR(robust.value * robust.value, a * a * std::log1p(r * r / (a * a)),
                1e-12 * (1.0 + r * r));
    EXPECT_EQ(std::signbit(robust.value), std::signbit(r)) << r;
    const double h = 1e-7 * std::max(1.0, std::abs(r));
    const double numeric =
        (cauchy_residual(r + h, a).value - cauchy_residual(r - h, a).value) / (2.0 * h);
    EXPECT_NEAR(robust.slope, numeric, 1e-5) << r;
  }
}

TEST(PointToPlaneCosts, PairwiseJacobiansMatchNumericDifferentiation) {
  std::mt19937 random(7);
  const std::vector<PlaneCorrespondence> matches = random_matches(40, random);
  const PointToPlaneCost cost(matches, 0.05);
  ceres::EigenQuaternionManifold quaternion;
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Quaterniond q = random_rotation(random);
    const Eigen::Vector3d t(0.3 * trial, -1.0, 2.0);
    expect_gradients_match(cost, {&quaternion, nullptr}, {q.coeffs().data(), t.data()});
  }
}

TEST(PointToPlaneCosts, BlocksCoverEveryCorrespondenceOnce) {
  std::mt19937 random(5);
  const std::vector<PlaneCorrespondence> matches =
      random_matches(2 * kCorrespondencesPerBlock + 3, random);
  const auto blocks = correspondence_blocks(matches);
  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_EQ(blocks[0].data(), matches.data());
  EXPECT_EQ(blocks[1].data(), matches.data() + kCorrespondencesPerBlock);
  EXPECT_EQ(blocks[2].size(), 3u);
  EXPECT_TRUE(correspondence_blocks({}).empty());
}

}  // namespace
}  // namespace scanbench::registration
