#include <gtest/gtest.h>

#include <numbers>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {
namespace {

Scan panorama(int columns, double azimuth_step_rad) {
  Scan scan = make_empty_scan(2, columns, false, false);
  scan.angles = SphericalAngles{0.3, azimuth_step_rad, 0.1, -0.01};
  return scan;
}

TEST(WrapsAround, AFullTurnOfColumnsInEitherDirection) {
  const double step = 2.0 * std::numbers::pi / 3600;
  EXPECT_TRUE(wraps_around(panorama(3600, step)));
  EXPECT_TRUE(wraps_around(panorama(3600, -step)));
}

TEST(WrapsAround, WithinHalfAStepOfTheTurn) {
  const double step = 2.0 * std::numbers::pi / 3600;
  EXPECT_TRUE(wraps_around(panorama(3600, step * (1.0 + 0.4 / 3600))));
  EXPECT_FALSE(wraps_around(panorama(3600, step * (1.0 + 0.6 / 3600))));
  EXPECT_FALSE(wraps_around(panorama(3599, step)));  // one column short of the turn
}

TEST(WrapsAround, PartialPanoramasAndPerPixelGridsDoNot) {
  EXPECT_FALSE(wraps_around(panorama(1800, 2.0 * std::numbers::pi / 3600)));
  Scan irregular = make_empty_scan(2, 3, false, false);
  irregular.angles = PerPixelDirections{std::vector<Eigen::Vector3f>(6, Eigen::Vector3f::UnitX())};
  EXPECT_FALSE(wraps_around(irregular));
}

}  // namespace
}  // namespace scanbench::acquisition
