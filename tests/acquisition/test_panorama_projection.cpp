// Unstructured points into a panoramic grid: a scan sampled on a regular
// grid comes back as that grid, one point per pixel; a partial panorama
// across ±180° stays whole; the nearer of two points on one pixel wins.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "acquisition/formats/panorama_projection.hpp"

namespace scanbench::acquisition {
namespace {

Eigen::Vector3d at(double azimuth, double elevation, double range) {
  return range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                 std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
}

TEST(PanoramaProjection, ARegularScanComesBackAsItsGrid) {
  constexpr int kRows = 90, kColumns = 360;
  const double step = 2.0 * std::numbers::pi / kColumns;
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kColumns; ++c) {
      if (r < 20 && c % 3 != 0) continue;  // a sparse band, as the sky gives
      points.push_back(at(-std::numbers::pi + c * step, 0.6 - r * step, 10.0 + std::sin(0.1 * c)));
    }
  }
  std::shuffle(points.begin(), points.end(), std::mt19937(4));
  const PanoramaProjection projection = project_to_panorama(points);
  EXPECT_EQ(projection.rows, kRows);
  EXPECT_EQ(projection.columns, kColumns);
  EXPECT_NEAR(projection.step_rad, step, 1e-9);
  EXPECT_EQ(projection.collisions, 0u);
}

TEST(PanoramaProjection, APartialPanoramaAcrossTheBackIsNotSplit) {
  // 60° of azimuth centred on 180°: the grid spans 60°, not 360°.
  const double step = 0.5 * std::numbers::pi / 180.0;
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < 20; ++r) {
    for (int c = 0; c <= 120; ++c)
      points.push_back(at(5.0 * std::numbers::pi / 6.0 + c * step, r * step, 5.0));
  }
  const PanoramaProjection projection = project_to_panorama(points);
  EXPECT_EQ(projection.columns, 121);
  EXPECT_EQ(projection.rows, 20);
  EXPECT_EQ(projection.collisions, 0u);
}

TEST(PanoramaProjection, TheNearerOfTwoPointsOnAPixelWins) {
  std::vector<Eigen::Vector3d> points;
  const double step = 0.01;
  for (int r = 0; r < 10; ++r) {
    for (int c = 0; c < 10; ++c) points.push_back(at(c * step, r * step, 8.0));
  }
  points.push_back(2.0 * points[34]);               // behind point 34
  points.insert(points.begin(), 0.5 * points[56]);  // in front of point 56 (now 57)
  const PanoramaProjection projection = project_to_panorama(points);
  EXPECT_EQ(projection.collisions, 2u);
  EXPECT_EQ(projection.pixel.back(), -1) << "the farther point is the collision";
  EXPECT_GE(projection.pixel.front(), 0) << "the nearer point keeps the pixel";
  EXPECT_EQ(projection.pixel[57], -1);
}

TEST(PanoramaProjection, ScatteredPointsGetAtMostFourPixelsEach) {
  std::vector<Eigen::Vector3d> points;
  std::mt19937 random(2);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 20000; ++i) {
    points.push_back(20.0 *
                     Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized());
  }
  const PanoramaProjection projection = project_to_panorama(points);
  EXPECT_LE(static_cast<double>(projection.rows) * projection.columns, 4.1 * points.size());
  std::size_t placed = 0;
  for (const std::int64_t p : projection.pixel) placed += p >= 0 ? 1 : 0;
  EXPECT_EQ(placed + projection.collisions, points.size());
}

}  // namespace
}  // namespace scanbench::acquisition
