// The covariance fallback of the geometry stage on hand-built grids.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "acquisition/geometry/grid_covariance.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using scanbench::test::kDeg;

// A spherical grid at 0.2° steps looking around +x, its ranges from `range`
// (≤ 0: no return), with the mask and NaN-marked log-range the fit reads.
struct Grid {
  Scan scan;
  std::vector<std::uint8_t> mask;
  std::vector<float> log_range;
};

template <typename Range>
Grid make_grid(int rows, int columns, Range&& range) {
  Grid g{make_empty_scan(rows, columns, false, false), {}, {}};
  const double step = 0.2 * kDeg;
  g.scan.angles = SphericalAngles{0.5 * columns * step, -step, 0.5 * rows * step, -step};
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < columns; ++col) {
      const float r = static_cast<float>(range(direction_precise(g.scan, row, col), row, col));
      g.mask.push_back(r > 0.0f);
      g.scan.valid[g.scan.index(row, col)] = r > 0.0f;
      g.scan.range_m[g.scan.index(row, col)] = r > 0.0f ? r : 0.0f;
      g.log_range.push_back(r > 0.0f ? std::log(r) : std::numeric_limits<float>::quiet_NaN());
    }
  }
  return g;
}

NormalFit fit(const Grid& g, int row, int col) {
  return covariance_fit(GridDirections(g.scan), g.scan.range_m.data(), g.mask.data(),
                        g.log_range.data(), row, col, g.scan.rows, GeometrySettings{});
}

TEST(GridCovariance, APlaneGivesItsNormalTowardsTheScanner) {
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 0.3, -0.2).normalized();
  const Grid g =
      make_grid(9, 9, [&](const Eigen::Vector3d& d, int, int) { return 8.0 / n.dot(d); });
  const NormalFit f = fit(g, 4, 4);
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.used, 25);
  EXPECT_LT(std::acos(std::min(1.0, f.normal.cast<double>().dot(-n))), 0.05 * kDeg);
  EXPECT_NEAR(f.cos_incidence, std::abs(f.normal.dot(direction(g.scan, 4, 4))), 1e-6);
}

TEST(GridCovariance, NeighboursAcrossAStepAreLeftOut) {
  // A wall at 8 m in the left columns, one at 12 m in the right ones.
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 0.0, 0.3).normalized();
  const Grid g = make_grid(9, 9, [&](const Eigen::Vector3d& d, int, int col) {
    return col <= 4 ? 8.0 / n.dot(d) : 12.0 / d.x();
  });
  const NormalFit f = fit(g, 4, 4);
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.used, 15);  // columns 2 … 4 only
  EXPECT_LT(std::acos(std::min(1.0, f.normal.cast<double>().dot(-n))), 0.05 * kDeg);
}

TEST(GridCovariance, LanesEqualSinglePixelFitsBitForBit) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Grid g = make_grid(24, 40, [&](const Eigen::Vector3d& d, int row, int col) {
    if ((row * 7 + col * 3) % 11 == 0) return -1.0;  // scattered missing returns
    return (col < 20 ? 6.0 : 9.0) / d.x() + noise(rng);
  });
  const GridDirections directions(g.scan);
  const GeometrySettings settings;
  int compared = 0;
  for (int row = 0; row < g.scan.rows; ++row) {
    for (int col = 0; col < g.scan.columns; ++col) {
      if (!covariance_lanes_fit(directions, row, col, g.scan.rows, settings)) continue;
      NormalFit lanes[kCovarianceLanes];
      covariance_fits(directions, g.scan.range_m.data(), g.log_range.data(), row, col, g.scan.rows,
                      settings, 0b1111u, lanes);
      for (int j = 0; j < kCovarianceLanes; ++j) {
        if (!g.mask[g.scan.index(row, col + j)]) continue;
        const NormalFit one = fit(g, row, col + j);
        ASSERT_EQ(lanes[j].ok, one.ok) << row << "," << col + j;
        ASSERT_EQ(lanes[j].used, one.used) << row << "," << col + j;
        ASSERT_EQ(lanes[j].normal, one.normal) << row << "," << col + j;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 1000);
}

}  // namespace
}  // namespace scanbench::acquisition
