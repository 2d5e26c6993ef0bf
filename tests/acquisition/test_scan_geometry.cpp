// Footprints, normals and mixed-pixel flags on hand-built grids with exact answers.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <numbers>
#include <random>
#include <utility>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/geometry/window_moments.hpp"
#include "acquisition/local_origin.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using scanbench::test::kDeg;

// A spherical scan of `rows` × `columns` at `step_deg`, looking around +x,
// whose range along a direction comes from `cast` (≤ 0: no return).
Scan cast_scan(int rows, int columns, double step_deg,
               const std::function<double(const Eigen::Vector3d&)>& cast) {
  Scan scan = make_empty_scan(rows, columns, false, false);
  const double step = step_deg * kDeg;
  scan.angles = SphericalAngles{0.5 * columns * step, -step, 0.5 * rows * step, -step};
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < columns; ++col) {
      const double range = cast(direction_precise(scan, row, col));
      const std::size_t i = scan.index(row, col);
      scan.valid[i] = range > 0;
      scan.range_m[i] = range > 0 ? static_cast<float>(range) : 0.0f;
    }
  }
  return scan;
}

// Distance along d to the plane n·p = offset (n unit), or −1.
double plane(const Eigen::Vector3d& d, const Eigen::Vector3d& n, double offset) {
  const double denominator = n.dot(d);
  if (std::abs(denominator) < 1e-9) return -1;
  const double t = offset / denominator;
  return t > 0 ? t : -1;
}

double angle_deg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0f, 1.0f)) / kDeg;
}

GeometrySettings exact_settings() {
  GeometrySettings settings;
  settings.threads = 1;
  return settings;
}

TEST(ScanGeometry, TiltedPlaneGetsItsNormalTowardsTheScanner) {
  // Seen at 5°–30° incidence, and at 72°–80° (a slope ahead, as ground is).
  for (const Eigen::Vector3d& n : {Eigen::Vector3d(1.0, 0.3, -0.2).normalized(),
                                   Eigen::Vector3d(0.25, 0.0, -1.0).normalized()}) {
    const double offset = n.z() < -0.5 ? 1.6 : 10.0;
    const Scan scan =
        cast_scan(40, 60, 0.2, [&](const Eigen::Vector3d& d) { return plane(d, n, offset); });
    const GeometryResult result = compute_geometry(scan, exact_settings());
    const Eigen::Vector3f expected = (-n).cast<float>();
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.columns; ++col) {
        const std::size_t i = scan.index(row, col);
        ASSERT_TRUE(result.geometry.has_normal(i)) << row << "," << col;
        // The window fit of the inverse range is exact for a plane at any
        // incidence; what is left is float rounding.
        ASSERT_LT(angle_deg(result.geometry.normal[i], expected), 0.002) << row << "," << col;
        ASSERT_EQ(result.geometry.flags[i], 0) << row << "," << col;
      }
    }
    EXPECT_EQ(result.normals, scan.pixel_count());
  }
}

TEST(ScanGeometry, FootprintClosesTheGapAndGrowsAtGrazingIncidence) {
  // A wall facing the scanner at 10 m: spacing = 10 m · 0.2°, at the centre.
  const Scan facing = cast_scan(21, 21, 0.2, [](const Eigen::Vector3d& d) {
    return plane(d, Eigen::Vector3d::UnitX(), 10.0);
  });
  const GeometryResult a = compute_geometry(facing, exact_settings());
  const std::size_t centre = facing.index(10, 10);
  const double spacing = facing.range_m[centre] * 0.2 * kDeg;
  EXPECT_NEAR(a.geometry.footprint_m[centre], 0.5 * std::sqrt(2.0) * spacing, 1e-3 * spacing);
  // The same wall turned 60° away: the footprint is twice as large.
  const Eigen::Vector3d turned(std::cos(60 * kDeg), std::sin(60 * kDeg), 0.0);
  const Scan grazing =
      cast_scan(21, 21, 0.2, [&](const Eigen::Vector3d& d) { return plane(d, turned, 10.0); });
  const GeometryResult b = compute_geometry(grazing, exact_settings());
  const double spacing_b = grazing.range_m[centre] * 0.2 * kDeg;
  EXPECT_NEAR(b.geometry.footprint_m[centre], 0.5 * std::sqrt(2.0) * spacing_b / 0.5,
              0.01 * spacing_b);
}

TEST(ScanGeometry, BoxCornerGivesEachWallItsOwnNormal) {
  // Walls x = 10 and y = 3 meeting in a vertical crease: whichever is nearer.
  const auto corner = [](const Eigen::Vector3d& d) {
    double best = 1e9;
    for (const auto& [n, offset] :
         {std::pair{Eigen::Vector3d::UnitX(), 10.0}, std::pair{Eigen::Vector3d::UnitY(), 3.0}}) {
      const double t = plane(d, n, offset);
      if (t > 0) best = std::min(best, t);
    }
    return best < 1e8 ? best : -1.0;
  };
  const Scan scan = cast_scan(30, 120, 0.25, corner);
  const GeometryResult result = compute_geometry(scan, exact_settings());
  int checked = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (!result.geometry.has_normal(i)) continue;
      const Eigen::Vector3f n = result.geometry.normal[i];
      const double to_x = angle_deg(n, -Eigen::Vector3f::UnitX()),
                   to_y = angle_deg(n, -Eigen::Vector3f::UnitY());
      ASSERT_LT(std::min(to_x, to_y), 1.0) << row << "," << col;  // never a blend of both walls
      ++checked;
    }
  }
  EXPECT_GT(checked, static_cast<int>(0.95 * scan.pixel_count()));
}

TEST(ScanGeometry, SphereNormalsPointFromTheCentre) {
  const Eigen::Vector3d centre(8.0, 0.0, 0.0);
  const double radius = 3.0;
  const auto sphere = [&](const Eigen::Vector3d& d) {
    const double b = d.dot(centre), c = centre.squaredNorm() - radius * radius, disc = b * b - c;
    return disc > 0 ? b - std::sqrt(disc) : -1.0;
  };
  const Scan scan = cast_scan(60, 60, 0.3, sphere);
  const GeometryResult result = compute_geometry(scan, exact_settings());
  int checked = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (!scan.valid[i] || !result.geometry.has_normal(i)) continue;
      const Eigen::Vector3d p = point_in_scan(scan, row, col).cast<double>();
      const Eigen::Vector3f truth = (p - centre).normalized().cast<float>();
      if (truth.dot(direction(scan, row, col)) > -0.3f) continue;  // skip the grazing rim
      // A window cut by the grid's border fits a chord of the sphere: a bias
      // of about half the window's angle on the sphere.
      const bool border = std::min({row, col, scan.rows - 1 - row, scan.columns - 1 - col}) < 3;
      ASSERT_LT(angle_deg(result.geometry.normal[i], truth), border ? 3.0 : 0.5)
          << row << "," << col;
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
}

// A wall at 10 m in front of a wall at 20 m: the pixels next to the step keep
// their own wall's normal (neighbours across the step are left out) and are
// flagged as edges.
Scan step_scan() {
  return cast_scan(20, 40, 0.2, [](const Eigen::Vector3d& d) {
    const Eigen::Vector3d n =
        d.y() > 0 ? Eigen::Vector3d(1, 0.2, 0).normalized() : Eigen::Vector3d::UnitX();
    return plane(d, n, d.y() > 0 ? 10.0 : 20.0);
  });
}

TEST(ScanGeometry, DepthStepKeepsEachSideClean) {
  const Scan scan = step_scan();
  const GeometryResult result = compute_geometry(scan, exact_settings());
  int edges = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      const bool near = direction(scan, row, col).y() > 0;
      const Eigen::Vector3f truth = near
                                        ? Eigen::Vector3f(-Eigen::Vector3f(1, 0.2f, 0).normalized())
                                        : Eigen::Vector3f(-Eigen::Vector3f::UnitX());
      ASSERT_TRUE(result.geometry.has_normal(i)) << row << "," << col;
      ASSERT_LT(angle_deg(result.geometry.normal[i], truth), 0.05) << row << "," << col;
      edges += (result.geometry.flags[i] & kFlagEdge) != 0;
    }
  }
  EXPECT_EQ(edges, 2 * scan.rows);  // one pixel on each side of the step, every row
}

TEST(ScanGeometry, AMixedPixelAtTheStepIsFlaggedWithoutANormalAndLeftOutOfItsNeighboursFits) {
  // Halfway to the far wall, and 1 % of the way: the second is within the
  // covariance fallback's 2 % of its neighbour, which must still leave it out.
  for (const float share : {0.5f, 0.01f}) {
    Scan scan = step_scan();
    // Column 19 is the last near pixel of every row; make row 10's a blend.
    const std::size_t i = scan.index(10, 19);
    const std::size_t behind = scan.index(10, 20);
    scan.range_m[i] = (1.0f - share) * scan.range_m[i] + share * scan.range_m[behind];
    const GeometryResult result = compute_geometry(scan, exact_settings());
    EXPECT_TRUE(result.geometry.is_mixed(i)) << share;
    EXPECT_EQ(result.mixed_pixels, 1u) << share;
    EXPECT_FALSE(result.geometry.has_normal(i)) << share;
    EXPECT_TRUE(result.geometry.flags[i] & kFlagNoNormal) << share;
    EXPECT_LT(angle_deg(result.geometry.normal[scan.index(10, 18)],
                        -Eigen::Vector3f(1, 0.2f, 0).normalized()),
              0.05)
        << share;
  }
}

TEST(ScanGeometry, ABlendWithinAFewSigmasOfItsSurfaceIsFoundUnderANoisySensor) {
  // σ = 10 cm (a structured-light sensor's at 8 m): a blend 40 cm behind the
  // near wall is 4 σ off it, and 1.3 m in front of the far one.
  Scan scan = step_scan();
  const std::size_t i = scan.index(10, 19), behind = scan.index(10, 20);
  scan.range_m[i] = 0.96f * scan.range_m[i] + 0.04f * scan.range_m[behind];
  GeometrySettings settings = exact_settings();
  settings.range_noise = {0.1, 0.0, 0.0};
  const GeometryResult result = compute_geometry(scan, settings);
  EXPECT_TRUE(result.geometry.is_mixed(i));
  EXPECT_EQ(result.mixed_pixels, 1u);
}

// A wall at 10 m with a step of `step_m` down its middle and, in every row,
// the pixel at the step halfway between the two sides.
Scan halfway_step_scan(double step_m) {
  Scan scan = cast_scan(20, 40, 0.2, [&](const Eigen::Vector3d& d) {
    return plane(d, Eigen::Vector3d::UnitX(), d.y() > 0 ? 10.0 : 10.0 + step_m);
  });
  for (int row = 0; row < scan.rows; ++row) {
    const std::size_t i = scan.index(row, 19), behind = scan.index(row, 20);
    scan.range_m[i] = 0.5f * (scan.range_m[i] + scan.range_m[behind]);
  }
  return scan;
}

TEST(ScanGeometry, ReliefSmallerThanADepthDiscontinuityIsNoBlend) {
  // σ = 1 mm (a phase-shift scanner's): the halfway pixels miss both sides
  // by 50 σ, yet the sides are 1 % of the range apart, no discontinuity (a
  // moulding, a leaf); at 3 % they are one, and the pixels are blends.
  GeometrySettings settings = exact_settings();
  settings.range_noise = {0.001, 0.0, 0.0};
  EXPECT_EQ(compute_geometry(halfway_step_scan(0.1), settings).mixed_pixels, 0u);
  EXPECT_EQ(compute_geometry(halfway_step_scan(0.3), settings).mixed_pixels, 20u);
}

TEST(ScanGeometry, NoisyPlaneHasFewFalseMixedPixelsAndSmallErrors) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.005);
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, -0.4, 0.1).normalized();
  const Scan scan = cast_scan(
      100, 200, 0.1, [&](const Eigen::Vector3d& d) { return plane(d, n, 15.0) + noise(rng); });
  const GeometryResult result = compute_geometry(scan, exact_settings());
  EXPECT_LT(result.mixed_pixels, scan.pixel_count() / 500);
  std::vector<double> errors;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    if (result.geometry.has_normal(i))
      errors.push_back(angle_deg(result.geometry.normal[i], (-n).cast<float>()));
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 3.0);
}

TEST(ScanGeometry, IsolatedPixelGetsAnExplicitlyInvalidNormal) {
  Scan scan = cast_scan(
      9, 9, 0.2, [](const Eigen::Vector3d& d) { return plane(d, Eigen::Vector3d::UnitX(), 5.0); });
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) scan.valid[i] = i == scan.index(4, 4);
  const GeometryResult result = compute_geometry(scan, exact_settings());
  const std::size_t i = scan.index(4, 4);
  EXPECT_FALSE(result.geometry.has_normal(i));
  EXPECT_EQ(result.geometry.normal[i], Eigen::Vector3f::Zero());
  EXPECT_TRUE(result.geometry.flags[i] & kFlagNoNormal);
  EXPECT_GT(result.geometry.footprint_m[i], 0.0f);
  EXPECT_EQ(result.geometry.footprint_m[0], 0.0f);  // invalid pixel
}

TEST(ScanGeometry, PerPixelDirectionGridsUseTheirPoints) {
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 0.2, 0.3).normalized();
  Scan scan = cast_scan(20, 20, 0.5, [&](const Eigen::Vector3d& d) { return plane(d, n, 4.0); });
  PerPixelDirections per_pixel;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col)
      per_pixel.directions.push_back(direction(scan, row, col));
  }
  scan.angles = per_pixel;
  const GeometryResult result = compute_geometry(scan, exact_settings());
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    ASSERT_TRUE(result.geometry.has_normal(i));
    ASSERT_LT(angle_deg(result.geometry.normal[i], (-n).cast<float>()), 0.01);
  }
}

TEST(ScanGeometry, ResultDoesNotDependOnTheThreadCount) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Scan scan = cast_scan(50, 80, 0.2, [&](const Eigen::Vector3d& d) {
    return plane(d, d.z() > 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d(0.5, 0, -1).normalized(),
                 6.0) +
           noise(rng);
  });
  GeometrySettings two = exact_settings();
  two.threads = 2;
  const GeometryResult a = compute_geometry(scan, exact_settings()),
                       b = compute_geometry(scan, two);
  EXPECT_EQ(a.geometry.normal, b.geometry.normal);
  EXPECT_EQ(a.geometry.flags, b.geometry.flags);
  EXPECT_EQ(a.geometry.footprint_m, b.geometry.footprint_m);
}

// Equal bit for bit (a vector of plain values, or one).
template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}
template <typename T>
bool same_bytes(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Rows [first, end) of `scan`, as the geometry stage holds a band of them.
Scan held_rows(const Scan& scan, int first, int end) {
  Scan held = without_arrays(scan);
  held.rows = end - first;
  const auto begin = static_cast<std::ptrdiff_t>(scan.index(first, 0));
  const auto stop = static_cast<std::ptrdiff_t>(scan.index(end, 0));
  held.range_m.assign(scan.range_m.begin() + begin, scan.range_m.begin() + stop);
  held.valid.assign(scan.valid.begin() + begin, scan.valid.begin() + stop);
  if (const auto* per_pixel = std::get_if<PerPixelDirections>(&scan.angles)) {
    held.angles = PerPixelDirections{
        {per_pixel->directions.begin() + begin, per_pixel->directions.begin() + stop}, false};
  }
  return held;
}

// The geometry of `scan` computed band by band, `tiles` of the window fits'
// row tiles a band, its σ(range) from bands of 48 rows: as the geometry
// stage computes a scan too large to hold.
GeometryResult geometry_by_bands(const Scan& scan, GeometrySettings settings, int tiles) {
  NoiseTiles noise(scan.rows, scan.columns, false);
  for (int begin = 0; begin < scan.rows; begin += 48) {
    const int end = std::min(scan.rows, begin + 48);
    const int first = std::max(0, begin - NoiseTiles::kHaloRows);
    noise.add(held_rows(scan, first, std::min(scan.rows, end + NoiseTiles::kHaloRows)),
              {scan.rows, first, begin, end});
  }
  GeometryResult result;
  result.noise = noise.finish(settings.range_noise);
  settings.range_noise = result.noise.noise;
  const std::vector<int> cuts = geometry_band_cuts(scan.rows);
  const int halo = geometry_halo_rows(settings);
  for (std::size_t k = 0; k + 1 < cuts.size(); k += static_cast<std::size_t>(tiles)) {
    const int begin = cuts[k], end = cuts[std::min(k + tiles, cuts.size() - 1)];
    const int first = std::max(0, begin - halo);
    const GeometryResult band =
        compute_geometry_rows(held_rows(scan, first, std::min(scan.rows, end + halo)),
                              {scan.rows, first, begin, end}, settings);
    ScanGeometry& g = result.geometry;
    const auto append = [](auto& to, const auto& from) {
      to.insert(to.end(), from.begin(), from.end());
    };
    append(g.footprint_m, band.geometry.footprint_m), append(g.normal, band.geometry.normal);
    append(g.confidence, band.geometry.confidence), append(g.flags, band.geometry.flags);
    result.valid_points += band.valid_points, result.normals += band.normals;
    result.mixed_pixels += band.mixed_pixels, result.edge_pixels += band.edge_pixels;
  }
  return result;
}

void expect_same_geometry(const GeometryResult& a, const GeometryResult& b) {
  EXPECT_TRUE(same_bytes(a.geometry.normal, b.geometry.normal));
  EXPECT_TRUE(same_bytes(a.geometry.footprint_m, b.geometry.footprint_m));
  EXPECT_TRUE(same_bytes(a.geometry.confidence, b.geometry.confidence));
  EXPECT_EQ(a.geometry.flags, b.geometry.flags);
  EXPECT_EQ(a.valid_points, b.valid_points);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.mixed_pixels, b.mixed_pixels);
  EXPECT_EQ(a.edge_pixels, b.edge_pixels);
}

TEST(ScanGeometry, BandsOfRowsGiveTheWholeScansGeometryBitForBit) {
  // Ground, a wall and a pillar before it (depth steps, so edges, fallback
  // fits and blends at the pillar's sides), sky, noise and dropouts, over
  // 700 rows: three tiles of the window fits.
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.003);
  std::uniform_real_distribution<double> uniform;
  Scan scan = cast_scan(700, 160, 0.1, [&](const Eigen::Vector3d& d) {
    if (d.y() > 0.1 && uniform(rng) < 0.01) return -1.0;  // dropouts, on one side only
    const double ground = plane(d, Eigen::Vector3d(0.0, 0.0, -1.0), 1.5);
    const double wall = plane(d, Eigen::Vector3d(1.0, 0.2, 0.0).normalized(), 12.0);
    double range = ground < 0 ? wall : (wall < 0 ? ground : std::min(ground, wall));
    if (std::abs(d.y() / d.x()) < 0.02 && d.z() > -0.1) range = std::min(range, 6.0 / d.x());
    return range < 0 || range > 40.0 ? -1.0 : range + noise(rng);
  });
  for (int i = 0; i < 40; ++i) {  // blends at the pillar's edge
    const std::size_t pixel = scan.index(100 + 13 * i, 80 + (i % 2 ? 9 : -9));
    if (scan.valid[pixel]) scan.range_m[pixel] = 9.0f;
  }
  GeometrySettings settings;
  settings.estimate_range_noise = true;
  const GeometryResult whole = compute_geometry(scan, settings);
  ASSERT_TRUE(whole.noise.estimated);
  ASSERT_GT(whole.mixed_pixels, 0u);
  ASSERT_GT(whole.edge_pixels, 0u);
  // Most of the wall and the ground get the widest window (a run of the
  // cascade down to the fallback fits near the edges).
  ASSERT_GT(whole.normals, scan.pixel_count() / 2);
  ASSERT_EQ(geometry_band_cuts(scan.rows).size(), 4u);
  for (const int tiles : {1, 2}) {
    SCOPED_TRACE(tiles);
    const GeometryResult banded = geometry_by_bands(scan, settings, tiles);
    EXPECT_TRUE(same_bytes(banded.noise.noise, whole.noise.noise));
    expect_same_geometry(banded, whole);
  }
  // A grid of per-pixel directions: covariance fits only.
  Scan per_pixel = scan;
  std::vector<Eigen::Vector3f> directions(scan.pixel_count());
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col)
      directions[scan.index(row, col)] = direction(scan, row, col);
  }
  per_pixel.angles = PerPixelDirections{std::move(directions), false};
  expect_same_geometry(geometry_by_bands(per_pixel, settings, 1),
                       compute_geometry(per_pixel, settings));
}

// Least-squares mean and slopes of v over the window of radius k around (r, c), by
// the normal equations of the plane fit; false when the window is not clean.
// Plain sums and Cramer's rule: the tests compile at -O0 under the sanitizers,
// where Eigen's small-matrix code over the 330 000 windows below took a minute.
bool brute_force_slopes(int rows, int columns, const std::vector<std::uint8_t>& clean,
                        const std::vector<float>& value, int r, int c, int k, double& mean,
                        double& b, double& slope_row) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, sv = 0, svx = 0, svy = 0;
  for (int dy = -k; dy <= k; ++dy) {
    for (int dx = -k; dx <= k; ++dx) {
      const int rr = r + dy, cc = c + dx;
      if (rr < 0 || rr >= rows || cc < 0 || cc >= columns || !clean[rr * columns + cc])
        return false;
      const double v = value[rr * columns + cc];
      n += 1, sx += dx, sy += dy, sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
      sv += v, svx += v * dx, svy += v * dy;
    }
  }
  // [n sx sy; sx sxx sxy; sy sxy syy] (mean, b, slope_row) = (sv, svx, svy).
  const auto det = [](double a, double b1, double c1, double d, double e, double f, double g,
                      double h, double i) {
    return a * (e * i - f * h) - b1 * (d * i - f * g) + c1 * (d * h - e * g);
  };
  const double whole = det(n, sx, sy, sx, sxx, sxy, sy, sxy, syy);
  mean = det(sv, sx, sy, svx, sxx, sxy, svy, sxy, syy) / whole;
  b = det(n, sv, sy, sx, svx, sxy, sy, svy, syy) / whole;
  slope_row = det(n, sx, sv, sx, sxx, svx, sy, sxy, svy) / whole;
  return true;
}

TEST(WindowSlopes, MatchBruteForceOnAMaskedGrid) {
  const int rows = 41, columns = 47;
  const std::vector<int> radii = {6, 3, 1};
  std::mt19937 rng(9);
  std::vector<std::uint8_t> clean(rows * columns);
  std::vector<float> value(rows * columns);
  for (int i = 0; i < rows * columns; ++i) {
    clean[i] = rng() % 40 != 0;
    value[i] = 3.0f + 0.01f * (i % columns) - 0.02f * (i / columns) +
               static_cast<float>(rng() % 1000) / 1e5f;
  }
  // Tiles must not show: a grid wider and taller than one tile.
  for (const auto& [r, c] : {std::pair{rows, columns}, std::pair{300, 1100}}) {
    std::vector<std::uint8_t> big_clean(static_cast<std::size_t>(r) * c);
    std::vector<float> big_value(big_clean.size());
    for (int i = 0; i < r * c; ++i) {
      big_clean[i] = clean[(i / c % rows) * columns + (i % c) % columns];
      big_value[i] = value[(i / c % rows) * columns + (i % c) % columns] + 1e-4f * (i % c);
    }
    const std::vector<WindowSlope> s = window_slopes(r, c, radii, big_clean, big_value, 2);
    for (int row = 0; row < r; ++row) {
      for (int col = 0; col < c; ++col) {
        const WindowSlope& got = s[static_cast<std::size_t>(row) * c + col];
        int expected_used = 0;
        double mean = 0, b = 0, slope_row = 0;
        for (const int k : radii) {
          if (!big_clean[static_cast<std::size_t>(row) * c + col]) break;
          if (brute_force_slopes(r, c, big_clean, big_value, row, col, k, mean, b, slope_row)) {
            expected_used = (2 * k + 1) * (2 * k + 1);
            break;
          }
        }
        ASSERT_EQ(got.used, expected_used) << row << "," << col;
        if (expected_used == 0) continue;
        ASSERT_NEAR(got.mean, mean, 1e-5) << row << "," << col;
        ASSERT_NEAR(got.per_column, b, 1e-6) << row << "," << col;
        ASSERT_NEAR(got.per_row, slope_row, 1e-6) << row << "," << col;
      }
    }
  }
}

// Ground (z = −1.6 m) and a wall 30 m ahead, seen from 2° above to 60°
// below the horizon at 0.25° steps (ranges 1.8 to 30 m), with Gaussian range
// noise of σ(range) = `truth`; in `rough` of its 8 × 8 pixel tiles the
// points instead lie off the surface by up to ±5 cm, as on bushes or rubble.
Scan noisy_ground(const RangeNoise& truth, double rough, std::uint32_t seed) {
  const double step = 0.25 * kDeg;
  Scan scan = make_empty_scan(248, 400, false, false);
  scan.angles = SphericalAngles{0.5 * scan.columns * step, -step, 2.0 * kDeg, -step};
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const Eigen::Vector3d d = direction_precise(scan, row, col);
      const double ground = plane(d, Eigen::Vector3d(0.0, 0.0, -1.0), 1.6);
      const double wall = plane(d, Eigen::Vector3d::UnitX(), 30.0);
      const double range = ground < 0 ? wall : (wall < 0 ? ground : std::min(ground, wall));
      const std::size_t i = scan.index(row, col);
      scan.valid[i] = range > 0;
      if (range <= 0) continue;
      const std::uint32_t tile = static_cast<std::uint32_t>(row / 8 * 1000 + col / 8) * 2654435761u;
      const bool bush = static_cast<double>(tile >> 8) / static_cast<double>(1u << 24) < rough;
      const double off = bush ? 0.1 * (uniform(rng) - 0.5) : 0.0;
      scan.range_m[i] = static_cast<float>(range + truth.sigma(range) * normal(rng) + off);
    }
  }
  return scan;
}

// The estimate's σ against the truth's at the ranges the scan covers well.
void expect_sigma_near(const NoiseEstimate& estimate, const RangeNoise& truth, double tolerance) {
  ASSERT_TRUE(estimate.estimated);
  EXPECT_GE(estimate.bands.size(), 8u);
  for (const double range : {3.0, 6.0, 12.0, 25.0}) {
    EXPECT_NEAR(estimate.noise.sigma(range) / truth.sigma(range), 1.0, tolerance)
        << "at " << range << " m: " << 1e3 * estimate.noise.sigma(range) << " mm, truth "
        << 1e3 * truth.sigma(range) << " mm";
  }
}

TEST(NoiseEstimate, FindsEachInstrumentsNoiseWithoutBeingTold) {
  const RangeNoise pulsed{0.005, 5e-5, 0.0};
  const RangeNoise phase_shift{0.0006, 2e-5, 2e-6};
  const RangeNoise triangulating{0.0, 0.0, 1.5e-4};
  for (const RangeNoise& truth : {pulsed, phase_shift, triangulating}) {
    const Scan scan = noisy_ground(truth, 0.0, 3);
    expect_sigma_near(estimate_range_noise(scan), truth, 0.1);
  }
}

TEST(NoiseEstimate, RoughSurfacesDoNotInflateIt) {
  const RangeNoise truth{0.002, 1e-5, 0.0};
  const NoiseEstimate estimate = estimate_range_noise(noisy_ground(truth, 0.2, 4));
  expect_sigma_near(estimate, truth, 0.2);
  // The same on one thread as on all.
  const NoiseEstimate single = estimate_range_noise(noisy_ground(truth, 0.2, 4), {}, 1);
  EXPECT_EQ(single.noise, estimate.noise);
}

// A wall 10 m ahead, head on: every range in one band.
Scan noisy_wall(double sigma_m, double quantum_m) {
  std::mt19937 rng(6);
  std::normal_distribution<double> normal;
  return cast_scan(64, 64, 0.1, [&](const Eigen::Vector3d& d) {
    const double range = plane(d, Eigen::Vector3d::UnitX(), 10.0) + sigma_m * normal(rng);
    return quantum_m > 0 ? quantum_m * std::round(range / quantum_m) : range;
  });
}

TEST(NoiseEstimate, OneBandOfRangeGivesAConstantSigma) {
  const NoiseEstimate estimate = estimate_range_noise(noisy_wall(0.003, 0.0));
  ASSERT_TRUE(estimate.estimated);
  EXPECT_EQ(estimate.bands.size(), 1u);
  EXPECT_NEAR(estimate.noise.noise_m, 0.003, 0.0003);
  EXPECT_EQ(estimate.noise.noise_per_m, 0.0);
  EXPECT_EQ(estimate.noise.noise_per_m2, 0.0);
}

TEST(NoiseEstimate, RangesQuantisedCoarserThanTheirNoiseKeepTheFallback) {
  const RangeNoise fallback{0.002, 0.0, 0.0};
  const NoiseEstimate estimate = estimate_range_noise(noisy_wall(0.001, 0.01), fallback);
  EXPECT_FALSE(estimate.estimated);
  EXPECT_EQ(estimate.noise, fallback);
}

TEST(NoiseEstimate, AScanWithoutGridLinesKeepsTheFallback) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 100; ++i) points.emplace_back(5.0, 0.01 * i, 0.0);
  Scan scattered = make_scattered_scan(points.size(), false, false);
  set_scattered_points(scattered, points);
  const RangeNoise fallback{0.003, 0.0, 0.0};
  const NoiseEstimate estimate = estimate_range_noise(scattered, fallback);
  EXPECT_FALSE(estimate.estimated);
  EXPECT_EQ(estimate.noise, fallback);
  // Told to estimate, the geometry stage reports what it used.
  GeometrySettings settings;
  settings.estimate_range_noise = true;
  settings.range_noise = fallback;
  EXPECT_EQ(compute_geometry(scattered, settings).noise.noise, fallback);
  const RangeNoise truth{0.004, 0.0, 0.0};
  const GeometryResult estimated = compute_geometry(noisy_ground(truth, 0.0, 5), settings);
  EXPECT_TRUE(estimated.noise.estimated);
  EXPECT_NEAR(estimated.noise.noise.sigma(10.0), 0.004, 0.0005);
}

}  // namespace
}  // namespace scanbench::acquisition

namespace scanbench::acquisition {
namespace {

// A scattered scan of a sphere (radius 1 m, centre (4, 1, 0.5)) sampled
// evenly, its far side behind its near side as seen from the origin, with
// the points in a shuffled order: neighbours in the list are not neighbours
// in space.
Scan scattered_sphere(int count) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < count; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / count, r = std::sqrt(1.0 - z * z);
    points.emplace_back(4.0 + r * std::cos(golden * k), 1.0 + r * std::sin(golden * k), 0.5 + z);
  }
  std::shuffle(points.begin(), points.end(), std::mt19937(5));
  Scan scan = make_scattered_scan(points.size(), false, false);
  set_scattered_points(scan, points);
  return scan;
}

TEST(ScatteredGeometry, ASphereSeenFromOutsideGetsItsNormalsFromItsNearestNeighbours) {
  const Scan scan = scattered_sphere(5000);
  ASSERT_EQ(check_consistency(scan), "");
  const GeometryResult result = compute_geometry(scan);
  EXPECT_EQ(result.valid_points, 5000u);
  EXPECT_EQ(result.normals, 5000u);
  EXPECT_EQ(result.mixed_pixels, 0u);
  // Mean spacing of 5 000 points on 4π m²: √(4π / 5000) ≈ 5.0 cm.
  const double spacing = std::sqrt(4.0 * std::numbers::pi / 5000.0);
  const Eigen::Vector3f centre(4.0f, 1.0f, 0.5f);
  int aligned = 0;
  for (std::size_t i = 0; i < 5000; ++i) {
    const Eigen::Vector3f p =
        point_in_scan(scan, static_cast<int>(i) / scan.columns, static_cast<int>(i) % scan.columns);
    const Eigen::Vector3f n = result.geometry.normal[i];
    EXPECT_GE(n.dot(-p), 0.0f) << "towards the viewpoint, the scan frame's origin";
    aligned += std::abs(n.dot((p - centre).normalized())) > 0.99f;
    EXPECT_GT(result.geometry.footprint_m[i], 0.5 * spacing);
    EXPECT_LT(result.geometry.footprint_m[i], 1.5 * spacing);
    EXPECT_GT(result.geometry.confidence[i], 0.0f);
  }
  EXPECT_GE(aligned, 4950) << "the radial direction, within 8°";
  // The same on one thread as on all.
  GeometrySettings one;
  one.threads = 1;
  const GeometryResult single = compute_geometry(scan, one);
  EXPECT_EQ(single.geometry.normal, result.geometry.normal);
  EXPECT_EQ(single.geometry.footprint_m, result.geometry.footprint_m);
}

TEST(ScatteredGeometry, APointFarFromTheOthersGetsNoNormal) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) points.emplace_back(5.0, 0.01 * i, 0.01 * j);
  }
  points.emplace_back(7.0, 3.0, 3.0);
  Scan scan = make_scattered_scan(points.size(), false, false);
  set_scattered_points(scan, points);
  const GeometryResult result = compute_geometry(scan);
  EXPECT_EQ(result.normals, 400u);
  EXPECT_TRUE(result.geometry.flags[400] & kFlagNoNormal);
  EXPECT_NEAR(std::abs(result.geometry.normal[0].x()), 1.0f, 1e-4f);
  const double spacing = 0.01;
  EXPECT_LT(result.geometry.footprint_m[400], 5.0 * spacing) << "no splat across the 3 m gap";
}

TEST(ScatteredGeometry, RepeatedPointsTakeTheirSpacingFromTheDistinctNeighbours) {
  // A plane sampled every centimetre, each point written three times (as
  // overlapping tiles or quantised coordinates repeat points).
  std::vector<Eigen::Vector3d> points;
  for (int copy = 0; copy < 3; ++copy) {
    for (int i = 0; i < 30; ++i) {
      for (int j = 0; j < 30; ++j) points.emplace_back(5.0, 0.01 * i, 0.01 * j);
    }
  }
  Scan scan = make_scattered_scan(points.size(), false, false);
  set_scattered_points(scan, points);
  const GeometryResult result = compute_geometry(scan);
  EXPECT_EQ(result.normals, points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_NEAR(result.geometry.footprint_m[i], 0.75 * 0.01, 1e-4) << "point " << i;
  }
}

// Ground 1.5 m below the origin, 8 × 8 m sampled every 4 cm (jittered),
// each point off it by Gaussian noise of `sigma_m`, and a bush: 6 000
// points strewn through a 1 m cube.
Scan noisy_cloud(double sigma_m) {
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i) {
    for (int j = 0; j < 200; ++j) {
      points.emplace_back(-4.0 + 0.04 * (i + 0.6 * unit(random)),
                          -4.0 + 0.04 * (j + 0.6 * unit(random)), -1.5 + sigma_m * noise(random));
    }
  }
  for (int k = 0; k < 6000; ++k)
    points.emplace_back(2.0 + unit(random), 1.0 + unit(random), -1.5 + unit(random));
  std::shuffle(points.begin(), points.end(), random);
  Scan scan = make_scattered_scan(points.size(), false, false);
  set_scattered_points(scan, points);
  return scan;
}

TEST(ScatteredGeometry, TheNoiseIsEstimatedFromThePointsPlanes) {
  GeometrySettings settings;
  settings.estimate_range_noise = true;
  settings.range_noise = RangeNoise{0.02, 0.0, 0.0};  // far off: the estimate must not be it
  for (const double sigma : {0.001, 0.003}) {
    const GeometryResult result = compute_geometry(noisy_cloud(sigma), settings);
    ASSERT_TRUE(result.noise.estimated) << sigma;
    EXPECT_NEAR(result.noise.noise.noise_m, sigma, 0.1 * sigma) << "despite the bush";
    EXPECT_EQ(result.noise.noise.noise_per_m, 0.0);
    EXPECT_EQ(result.noise.noise.noise_per_m2, 0.0);
    EXPECT_EQ(result.geometry.range_noise, result.noise.noise);
    EXPECT_GT(result.noise.samples, 30000u);
  }
  // A noiseless plane: the floor of 0.1 mm, not zero.
  EXPECT_EQ(compute_geometry(noisy_cloud(0.0), settings).noise.noise.noise_m, 1e-4);
  // Not told to estimate: the settings' model.
  EXPECT_EQ(compute_geometry(noisy_cloud(0.003)).noise.noise, RangeNoise{});
}

TEST(ScatteredGeometry, LinesDenserAlongThanAcrossStillSpanAPlane) {
  // A profiler's sampling: lines 2 cm apart, a point every millimetre along
  // them. The 16 nearest neighbours lie on the point's own line; the plane
  // comes from the wider neighbourhood reaching the next lines.
  std::vector<Eigen::Vector3d> points;
  for (int line = 0; line < 10; ++line) {
    for (int k = 0; k < 200; ++k) points.emplace_back(0.001 * k, 0.02 * line, 6.0);
  }
  Scan scan = make_scattered_scan(points.size(), false, false);
  set_scattered_points(scan, points);
  const GeometryResult result = compute_geometry(scan);
  EXPECT_GE(result.normals, points.size() * 95 / 100);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (result.geometry.flags[i] & kFlagNoNormal) continue;
    ASSERT_NEAR(result.geometry.normal[i].z(), -1.0f, 1e-3f) << "point " << i;
  }
}

}  // namespace
}  // namespace scanbench::acquisition
