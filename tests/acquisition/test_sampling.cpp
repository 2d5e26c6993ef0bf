// Sample areas on hand-built grids with exact answers.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "acquisition/geometry/sampling.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using scanbench::test::kDeg;

TEST(PixelSolidAngle, SphericalCellIsStepTimesStepTimesCosElevation) {
  Scan scan = make_empty_scan(40, 90, false, false);
  scan.angles = SphericalAngles{0.0, 4.0 * kDeg, 60.0 * kDeg, -3.0 * kDeg};
  for (int row : {0, 10, 20, 39}) {
    // The chord parallelogram is the cell to first order; at 4° and 3° steps
    // the second-order rest stays within 0.5 %.
    const double el = (60.0 - 3.0 * row) * kDeg;
    const double expected = 4.0 * kDeg * 3.0 * kDeg * std::cos(el);
    EXPECT_NEAR(pixel_solid_angle(scan, row, 7), expected, 5e-3 * expected) << row;
    // The last column takes the step back; the cell is the same.
    EXPECT_NEAR(pixel_solid_angle(scan, row, 89), pixel_solid_angle(scan, row, 7), 1e-4 * expected)
        << row;
  }
}

TEST(PixelSolidAngle, SingleRowGridHasNoCell) {
  Scan scan = make_empty_scan(1, 5, false, false);
  scan.angles = SphericalAngles{0.0, 0.01, 0.0, 0.01};
  EXPECT_EQ(pixel_solid_angle(scan, 0, 2), 0.0f);
}

TEST(SampleArea, GrowsWithRangeSquaredAndObliquityUpToTheClamp) {
  EXPECT_FLOAT_EQ(sample_area_m2(10.0f, 1e-4f, 1.0f), 1e-2f);
  EXPECT_FLOAT_EQ(sample_area_m2(10.0f, 1e-4f, -0.5f), 2e-2f);  // the normal's sign is free
  EXPECT_FLOAT_EQ(sample_area_m2(10.0f, 1e-4f, 0.0f), 1e-2f / kMinCosIncidence);
}

}  // namespace
}  // namespace scanbench::acquisition
