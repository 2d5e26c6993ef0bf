#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "acquisition/spherical_fit.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using scanbench::test::kDeg;

struct Grid {
  int rows;
  int columns;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::uint8_t> valid;
};

Grid make_grid(int rows, int columns, const SphericalAngles& a, double noise_rad = 0.0) {
  Grid grid{rows, columns, {}, {}};
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, noise_rad);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < columns; ++col) {
      const double az =
          a.azimuth_start_rad + col * a.azimuth_step_rad + (noise_rad > 0 ? noise(rng) : 0);
      const double el = a.elevation_start_rad + row * a.elevation_step_rad;
      const double range = 3.0 + 0.1 * ((row * 31 + col * 17) % 50);
      grid.points.emplace_back(range * std::cos(el) * std::cos(az),
                               range * std::cos(el) * std::sin(az), range * std::sin(el));
      grid.valid.push_back((row * 5 + col) % 11 != 0);
    }
  }
  return grid;
}

void expect_angles(const SphericalAngles& fit, const SphericalAngles& truth, double tolerance) {
  EXPECT_NEAR(fit.azimuth_step_rad, truth.azimuth_step_rad, tolerance);
  EXPECT_NEAR(fit.elevation_start_rad, truth.elevation_start_rad, tolerance);
  EXPECT_NEAR(fit.elevation_step_rad, truth.elevation_step_rad, tolerance);
  const double az_error =
      std::remainder(fit.azimuth_start_rad - truth.azimuth_start_rad, 2 * std::numbers::pi);
  EXPECT_NEAR(az_error, 0.0, tolerance);
}

TEST(SphericalFit, RecoversAnExactPanoramaAcrossTheAzimuthWrap) {
  const SphericalAngles truth{170 * kDeg, 0.5 * kDeg, 50 * kDeg, -0.25 * kDeg};  // crosses ±180°
  const Grid grid = make_grid(60, 120, truth);
  const SphericalFitResult fit =
      fit_spherical_angles(grid.rows, grid.columns, grid.points, grid.valid);
  ASSERT_TRUE(fit.regular);
  expect_angles(fit.angles, truth, 1e-12);
  EXPECT_LT(fit.max_deviation_m, 1e-9);
}

TEST(SphericalFit, RecoversDecreasingAzimuthAndIncreasingElevation) {
  const SphericalAngles truth{-20 * kDeg, -0.1 * kDeg, -40 * kDeg, 0.1 * kDeg};
  const Grid grid = make_grid(30, 40, truth);
  const SphericalFitResult fit =
      fit_spherical_angles(grid.rows, grid.columns, grid.points, grid.valid);
  ASSERT_TRUE(fit.regular);
  expect_angles(fit.angles, truth, 1e-12);
}

TEST(SphericalFit, RefusesAGridWhoseDirectionsJitterBeyondTolerance) {
  const SphericalAngles truth{0.0, 0.5 * kDeg, 10 * kDeg, -0.5 * kDeg};
  const Grid grid = make_grid(20, 20, truth, 0.001);  // ~1 mrad jitter, mm at 3 m
  const SphericalFitResult fit =
      fit_spherical_angles(grid.rows, grid.columns, grid.points, grid.valid);
  EXPECT_FALSE(fit.regular);
  EXPECT_GT(fit.max_deviation_m, 1e-4);
}

TEST(SphericalFit, NeedsAtLeastTwoValidPoints) {
  const std::vector<Eigen::Vector3d> points{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d::Zero()};
  const std::vector<std::uint8_t> valid{1, 0};
  EXPECT_FALSE(fit_spherical_angles(1, 2, points, valid).regular);
}

}  // namespace
}  // namespace scanbench::acquisition
