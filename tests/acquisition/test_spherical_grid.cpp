// Projective association on hand-built spherical grids with exact answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "acquisition/spherical_grid.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

constexpr double kPi = std::numbers::pi;
using scanbench::test::kDeg;

// A full panorama laid out like the virtual scanner's: column c looks at
// azimuth −(c + 0.5) · 360° / columns, row r at 45° − (r + 0.5) · 7.5°.
Scan panorama(int rows = 12, int columns = 36) {
  Scan scan = make_empty_scan(rows, columns, false, false);
  const double az_step = 2.0 * kPi / columns;
  const double el_step = 7.5 * kDeg;
  scan.angles = SphericalAngles{-0.5 * az_step, -az_step, 45.0 * kDeg - 0.5 * el_step, -el_step};
  return scan;
}

Eigen::Vector3d along(double azimuth, double elevation, double range = 1.0) {
  return range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                 std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
}

TEST(SphericalGrid, EveryPixelCentreMapsBackToItsPixel) {
  const Scan scan = panorama();
  const SphericalGrid grid(scan);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const auto expected = static_cast<std::int64_t>(scan.index(row, col));
      const Eigen::Vector3d d = direction_precise(scan, row, col);
      EXPECT_EQ(grid.pixel_of(d), expected) << row << "," << col;
      EXPECT_EQ(grid.pixel_of(Eigen::Vector3d(37.5 * d)), expected) << row << "," << col;
      const Eigen::Vector3f f = direction(scan, row, col) * 2.5f;
      EXPECT_EQ(grid.pixel_of(f), expected) << row << "," << col;
    }
  }
}

TEST(SphericalGrid, DirectionsWithinHalfAStepMapToTheNearestPixel) {
  const Scan scan = panorama();
  const SphericalGrid grid(scan);
  const auto& a = std::get<SphericalAngles>(scan.angles);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      for (const auto& [du, dv] : {std::pair{0.45, 0.45}, std::pair{-0.45, 0.45},
                                   std::pair{0.45, -0.45}, std::pair{-0.45, -0.45}}) {
        const double az = a.azimuth_start_rad + (col + du) * a.azimuth_step_rad;
        const double el = a.elevation_start_rad + (row + dv) * a.elevation_step_rad;
        EXPECT_EQ(grid.pixel_of(along(az, el, 8.0)), scan.index(row, col))
            << row << "," << col << " " << du << "," << dv;
      }
    }
  }
}

TEST(SphericalGrid, PointsAcrossTheAzimuthSeamWrapAround) {
  // Column 0 looks at −5°, the last column at −355° ≡ +5°: the seam at
  // azimuth 0 lies between them.
  const Scan scan = panorama();
  const SphericalGrid grid(scan);
  const int last = scan.columns - 1;
  for (int row = 0; row < scan.rows; ++row) {
    const double el = 45.0 * kDeg - (row + 0.5) * 7.5 * kDeg;
    EXPECT_EQ(grid.pixel_of(along(-0.5 * kDeg, el, 3.0)), scan.index(row, 0)) << row;
    EXPECT_EQ(grid.pixel_of(along(-9.9 * kDeg, el, 3.0)), scan.index(row, 0)) << row;
    EXPECT_EQ(grid.pixel_of(along(0.5 * kDeg, el, 3.0)), scan.index(row, last)) << row;
    EXPECT_EQ(grid.pixel_of(along(9.9 * kDeg, el, 3.0)), scan.index(row, last)) << row;
    // atan2 returns ±180° on the negative x axis: the middle of the circle.
    // (Column 17 looks at −175°, column 18 at −185° ≡ +175°.)
    EXPECT_EQ(grid.pixel_of(along(-179.9 * kDeg, el, 3.0)), scan.index(row, 17)) << row;
    EXPECT_EQ(grid.pixel_of(along(179.9 * kDeg, el, 3.0)), scan.index(row, 18)) << row;
    EXPECT_EQ(grid.pixel_of(along(-180.1 * kDeg, el, 3.0)), scan.index(row, 18)) << row;
  }
}

// For azimuth exactly 0, u wraps to exactly period − 0.5: the seam test must
// take it to column 0 rather than round it to column `columns`.
TEST(SphericalGrid, DirectionStraightAlongTheSeamFindsABorderPixel) {
  // Azimuth exactly 0 (y = 0, as any point on the x-z plane ahead gives) lies
  // half-way between the last column and column 0; either is a right answer,
  // none is not.
  const Scan scan = panorama();
  const SphericalGrid grid(scan);
  for (int row = 0; row < scan.rows; ++row) {
    const double el = 45.0 * kDeg - (row + 0.5) * 7.5 * kDeg;
    const Eigen::Vector3d p(std::cos(el), 0.0, std::sin(el));
    const std::int64_t pixel = grid.pixel_of(p);
    EXPECT_TRUE(pixel == static_cast<std::int64_t>(scan.index(row, 0)) ||
                pixel == static_cast<std::int64_t>(scan.index(row, scan.columns - 1)))
        << row << ": " << pixel;
  }
}

TEST(SphericalGrid, DirectionsOutsideTheElevationWindowAndTheOriginGiveNone) {
  // Rows cover elevations 45° down to −45°; pixel centres from 41.25° to −41.25°.
  const Scan scan = panorama();
  const SphericalGrid grid(scan);
  for (const double az : {-170.0, -90.0, -5.0, 0.3, 60.0, 135.0}) {
    EXPECT_EQ(grid.pixel_of(along(az * kDeg, 45.5 * kDeg)), -1) << az;
    EXPECT_EQ(grid.pixel_of(along(az * kDeg, -45.5 * kDeg)), -1) << az;
    EXPECT_EQ(grid.pixel_of(along(az * kDeg, 80.0 * kDeg)), -1) << az;
    EXPECT_GE(grid.pixel_of(along(az * kDeg, 44.5 * kDeg)), 0) << az;
    EXPECT_GE(grid.pixel_of(along(az * kDeg, -44.5 * kDeg)), 0) << az;
  }
  EXPECT_EQ(grid.pixel_of(Eigen::Vector3d(0.0, 0.0, 5.0)), -1);   // zenith
  EXPECT_EQ(grid.pixel_of(Eigen::Vector3d(0.0, 0.0, -5.0)), -1);  // nadir
  EXPECT_EQ(grid.pixel_of(Eigen::Vector3d::Zero().eval()), -1);
  EXPECT_EQ(grid.pixel_of(Eigen::Vector3f::Zero().eval()), -1);
}

TEST(SphericalGrid, PartialPanoramaDoesNotWrap) {
  // 20 columns of 1° from +10° to −9° (positive step too: 10 rows upward).
  Scan scan = make_empty_scan(10, 20, false, false);
  scan.angles = SphericalAngles{10.0 * kDeg, -1.0 * kDeg, -5.0 * kDeg, 1.0 * kDeg};
  const SphericalGrid grid(scan);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      EXPECT_EQ(grid.pixel_of(direction_precise(scan, row, col)), scan.index(row, col));
    }
  }
  EXPECT_EQ(grid.pixel_of(along(10.4 * kDeg, 0.0)), scan.index(5, 0));
  EXPECT_EQ(grid.pixel_of(along(10.6 * kDeg, 0.0)), -1);
  EXPECT_EQ(grid.pixel_of(along(-9.4 * kDeg, 0.0)), scan.index(5, 19));
  EXPECT_EQ(grid.pixel_of(along(-9.6 * kDeg, 0.0)), -1);
  EXPECT_EQ(grid.pixel_of(along(180.0 * kDeg, 0.0)), -1);  // behind the scanner
  EXPECT_EQ(grid.pixel_of(along(0.0, -5.4 * kDeg)), scan.index(0, 10));
  EXPECT_EQ(grid.pixel_of(along(0.0, -5.6 * kDeg)), -1);
  EXPECT_EQ(grid.pixel_of(along(0.0, 4.6 * kDeg)), -1);
}

TEST(FastAtan2, FollowsTheLibraryWithinItsBoundEverywhere) {
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double angle = -std::numbers::pi + 2.0 * std::numbers::pi * (i + 0.5) / 200000.0;
    for (const double length : {1e-3, 1.0, 37.0, 1e4}) {
      const auto x = static_cast<float>(length * std::cos(angle));
      const auto y = static_cast<float>(length * std::sin(angle));
      const double exact = std::atan2(static_cast<double>(y), static_cast<double>(x));
      worst = std::max(worst, std::abs(fast_atan2(y, x) - exact));
    }
  }
  EXPECT_LT(worst, 6e-7);
  EXPECT_FLOAT_EQ(fast_atan2(0.0f, -1.0f), std::numbers::pi_v<float>);
  EXPECT_FLOAT_EQ(fast_atan2(-0.0f, -1.0f), -std::numbers::pi_v<float>);
  EXPECT_EQ(fast_atan2(0.0f, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(fast_atan2(-2.0f, 0.0f), -std::numbers::pi_v<float> / 2);
  EXPECT_FLOAT_EQ(fast_atan2(3.0f, 3.0f), std::numbers::pi_v<float> / 4);
}

}  // namespace
}  // namespace scanbench::acquisition
