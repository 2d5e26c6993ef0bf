#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <string>
#include <vector>

#include "acquisition/formats/ptx_reader.hpp"
#include "acquisition/formats/ptx_writer.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::fixture;
using test::ScratchDir;

using scanbench::test::kDeg;

// Channels and pose must match bit for bit; the refitted angle model to 1e-12 rad.
void expect_same_scan(const Scan& a, const Scan& b) {
  ASSERT_EQ(a.rows, b.rows);
  ASSERT_EQ(a.columns, b.columns);
  EXPECT_EQ(a.range_m, b.range_m);
  EXPECT_EQ(a.valid, b.valid);
  EXPECT_EQ(a.intensity, b.intensity);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.T_world_scan.matrix(), b.T_world_scan.matrix());
  ASSERT_EQ(a.is_spherical(), b.is_spherical());
  if (a.is_spherical()) {
    const auto& x = std::get<SphericalAngles>(a.angles);
    const auto& y = std::get<SphericalAngles>(b.angles);
    EXPECT_NEAR(x.azimuth_start_rad, y.azimuth_start_rad, 1e-12);
    EXPECT_NEAR(x.azimuth_step_rad, y.azimuth_step_rad, 1e-12);
    EXPECT_NEAR(x.elevation_start_rad, y.elevation_start_rad, 1e-12);
    EXPECT_NEAR(x.elevation_step_rad, y.elevation_step_rad, 1e-12);
    return;
  }
  const auto& x = std::get<PerPixelDirections>(a.angles).directions;
  const auto& y = std::get<PerPixelDirections>(b.angles).directions;
  ASSERT_EQ(x.size(), y.size());
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_LT((x[i] - y[i]).norm(), 1e-6f) << i;
}

TEST(PtxReader, TinyColorScanHasExactGridRangesColoursAndAngles) {
  const std::vector<Scan> scans = read_ptx(fixture("good/ptx/tiny_color.ptx"));
  ASSERT_EQ(scans.size(), 1u);
  const Scan& scan = scans[0];
  EXPECT_EQ(scan.name, "tiny_color");
  ASSERT_EQ(scan.rows, 2);
  ASSERT_EQ(scan.columns, 3);
  ASSERT_TRUE(scan.is_spherical());
  const auto& angles = std::get<SphericalAngles>(scan.angles);
  EXPECT_NEAR(angles.azimuth_start_rad, 0.0, 1e-12);
  EXPECT_NEAR(angles.azimuth_step_rad, 10 * kDeg, 1e-12);
  EXPECT_NEAR(angles.elevation_start_rad, -5 * kDeg, 1e-12);
  EXPECT_NEAR(angles.elevation_step_rad, 10 * kDeg, 1e-12);
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) {
      const std::size_t i = scan.index(row, col);
      const int k = col * 2 + row;  // PTX order: column after column
      const bool missing = row == 1 && col == 2;
      EXPECT_EQ(scan.valid[i], missing ? 0 : 1);
      if (!missing) {
        EXPECT_EQ(scan.range_m[i], static_cast<float>(10 + row + 2 * col));
      }
      EXPECT_EQ(scan.intensity[i], 0.125f * (k + 1));
      EXPECT_EQ(scan.rgb[3 * i + 0], 10 * k);
      EXPECT_EQ(scan.rgb[3 * i + 1], 20 * k);
      EXPECT_EQ(scan.rgb[3 * i + 2], 255 - k);
    }
  }
  EXPECT_TRUE(scan.T_world_scan.matrix().isIdentity());
}

TEST(PtxReader, CrlfLineEndingsReadLikeLf) {
  const Scan lf = read_ptx(fixture("good/ptx/tiny_color.ptx")).at(0);
  const Scan crlf = read_ptx(fixture("good/ptx/tiny_color_crlf.ptx")).at(0);
  expect_same_scan(lf, crlf);
}

TEST(PtxReader, MultiScanFileKeepsEachTransformAsPose) {
  const std::vector<Scan> scans = read_ptx(fixture("good/ptx/two_scans.ptx"));
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].name, "two_scans");
  EXPECT_EQ(scans[1].name, "two_scans-2");
  EXPECT_EQ(scans[0].rows, 3);
  EXPECT_EQ(scans[0].columns, 4);
  EXPECT_FALSE(scans[0].has_color());
  EXPECT_TRUE(scans[1].has_intensity());
  const Eigen::Isometry3d& pose = scans[1].T_world_scan;
  EXPECT_EQ(pose.translation(), Eigen::Vector3d(512000.5, 5400000.25, 300.75));
  Eigen::Matrix3d rz90;
  rz90 << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_EQ(pose.linear(), rz90);
  EXPECT_EQ(scans[1].scanner.position_world, pose.translation());
  // Points stay in the scan frame: ranges are 20 m, not world distances.
  EXPECT_FLOAT_EQ(scans[1].range_m[0], 20.0f);
  const Eigen::Vector3d world = point_in_world(scans[1], 0, 0);
  EXPECT_NEAR((world - pose.translation()).norm(), 20.0, 1e-9);
}

TEST(PtxReader, IrregularGridFallsBackToPerPixelDirections) {
  const Scan scan = read_ptx(fixture("good/ptx/irregular.ptx")).at(0);
  ASSERT_FALSE(scan.is_spherical());
  // Point k = (row k % 2, col k / 2); point 2 is (3, 3, 3).
  const Eigen::Vector3f p = point_in_scan(scan, 0, 1);
  EXPECT_LT((p - Eigen::Vector3f(3, 3, 3)).norm(), 1e-5f);
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 2; ++col) EXPECT_NEAR(direction(scan, row, col).norm(), 1.0f, 1e-6f);
  }
}

TEST(PtxRoundTrip, ImportExportImportIsIdentical) {
  ScratchDir dir;
  for (const char* name : {"tiny_color.ptx", "two_scans.ptx", "irregular.ptx"}) {
    const std::vector<Scan> first = read_ptx(fixture(std::string("good/ptx/") + name));
    write_ptx(dir / name, first);
    const std::vector<Scan> second = read_ptx(dir / name);
    ASSERT_EQ(first.size(), second.size()) << name;
    for (std::size_t s = 0; s < first.size(); ++s) expect_same_scan(first[s], second[s]);
  }
}

TEST(PtxRoundTrip, GeoreferencedPanoramaKeepsMillimetresAndBits) {
  Scan scan = make_empty_scan(40, 90, true, true);
  scan.angles = SphericalAngles{-std::numbers::pi, 4 * kDeg, 50 * kDeg, -2.5 * kDeg};
  scan.T_world_scan = Eigen::Translation3d(654321.125, 5123456.5, 287.25) *
                      Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    scan.valid[i] = i % 7 != 0;
    scan.range_m[i] = scan.valid[i] ? 1.0f + 0.0137f * static_cast<float>(i) : 0.0f;
    scan.intensity[i] = static_cast<float>(i % 100) / 99.0f;
    for (int c = 0; c < 3; ++c) scan.rgb[3 * i + c] = static_cast<std::uint8_t>(i * (c + 1));
  }
  ScratchDir dir;
  write_ptx(dir / "geo.ptx", {&scan, 1});
  const Scan back = read_ptx(dir / "geo.ptx").at(0);
  expect_same_scan(scan, back);
  EXPECT_LT((point_in_world(scan, 5, 7) - point_in_world(back, 5, 7)).norm(), 1e-9);
}

// The x y z of every point line of a one-scan PTX file, in file order.
std::vector<Eigen::Vector3d> file_points(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  for (int header = 0; header < 10; ++header) std::getline(in, line);
  std::vector<Eigen::Vector3d> points;
  double x = 0, y = 0, z = 0, intensity = 0;
  while (in >> x >> y >> z >> intensity) points.emplace_back(x, y, z);
  return points;
}

// World coordinates at 10^5–10^7 m (identity transform) keep 0.1 mm: the
// scan frame sits at the header's scanner position, or near the points when
// the grid has no recoverable centre.
class PtxWorldCoordinates : public ::testing::TestWithParam<std::pair<const char*, bool>> {};

TEST_P(PtxWorldCoordinates, EveryPointKeepsATenthOfAMillimetre) {
  const auto [name, spherical] = GetParam();
  const std::filesystem::path path = fixture(std::string("good/ptx/") + name + ".ptx");
  const std::vector<Scan> scans = read_ptx(path);
  ASSERT_EQ(scans.size(), 1u);
  const Scan& scan = scans[0];
  EXPECT_EQ(scan.is_spherical(), spherical);
  const std::vector<Eigen::Vector3d> expected = file_points(path);
  ASSERT_EQ(expected.size(), scan.pixel_count());
  double worst = 0.0;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const int row = static_cast<int>(k % static_cast<std::size_t>(scan.rows));
    const int col = static_cast<int>(k / static_cast<std::size_t>(scan.rows));
    worst = std::max(worst, (point_in_world(scan, row, col) - expected[k]).norm());
  }
  EXPECT_LT(worst, 1e-4);
  // The scan frame is near the points, so its ranges are the scanner's.
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) EXPECT_LT(scan.range_m[i], 100.0f);
}

INSTANTIATE_TEST_SUITE_P(Magnitudes, PtxWorldCoordinates,
                         ::testing::Values(std::pair{"georef_world_1e5", true},
                                           std::pair{"georef_world_utm", true},
                                           std::pair{"georef_world_1e7", true},
                                           std::pair{"georef_world_unknown_centre", false}));

// Issue 27's case: a regular panorama around the header's scanner position,
// 3 km from the points. The grid fits, but float ranges of 3 km round by up
// to 0.12 mm: the reader must notice and fall back to directions from the
// points' centroid.
TEST(PtxWorldCoordinates, PointsFarFromTheHeadersScannerStillKeepATenthOfAMillimetre) {
  const int rows = 20, columns = 60;
  const Eigen::Vector3d scanner(637000.0, 8490000.0, 400.0);
  ScratchDir dir;
  const std::filesystem::path path = dir / "far_scanner.ptx";
  {
    std::ofstream out(path);
    out << columns << '\n'
        << rows << '\n'
        << std::fixed << std::setprecision(6) << scanner.x() << ' ' << scanner.y() << ' '
        << scanner.z() << '\n'
        << "1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
    for (int col = 0; col < columns; ++col) {
      for (int row = 0; row < rows; ++row) {
        const double azimuth = 0.3 + 5e-4 * col, elevation = 0.01 - 5e-4 * row;
        const double range = 3000.0 + 7.0 * std::sin(0.1 * col) + 0.37 * row;
        const Eigen::Vector3d p =
            scanner + range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                              std::cos(elevation) * std::sin(azimuth),
                                              std::sin(elevation));
        out << p.x() << ' ' << p.y() << ' ' << p.z() << " 0.5\n";
      }
    }
  }
  const std::vector<Scan> scans = read_ptx(path);
  ASSERT_EQ(scans.size(), 1u);
  const std::vector<Eigen::Vector3d> expected = file_points(path);
  ASSERT_EQ(expected.size(), scans[0].pixel_count());
  double worst = 0.0;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const int row = static_cast<int>(k % rows), col = static_cast<int>(k / rows);
    worst = std::max(worst, (point_in_world(scans[0], row, col) - expected[k]).norm());
  }
  EXPECT_LT(worst, 1e-4);
}

TEST(PtxRoundTrip, WorldCoordinateScansExportAndReimportLosslessly) {
  const ScratchDir dir;
  for (const char* name : {"georef_world_utm", "georef_world_unknown_centre"}) {
    const std::vector<Scan> first = read_ptx(fixture(std::string("good/ptx/") + name + ".ptx"));
    write_ptx(dir / "again.ptx", first);
    expect_same_scan(read_ptx(dir / "again.ptx").at(0), first.at(0));
  }
}

TEST(PtxReader, PathsWithSpacesAndNonAsciiCharactersWork) {
  ScratchDir dir;
  const std::filesystem::path path = dir / "façade scan 1.ptx";
  std::filesystem::copy_file(fixture("good/ptx/tiny_color.ptx"), path);
  const std::vector<Scan> scans = read_ptx(path);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(scans[0].name, "façade scan 1");
}

// Every malformed file is refused with an InputError naming the file, the line
// and the problem.
struct BadPtx {
  const char* file;
  const char* problem;  // a piece of the expected message
  bool has_line;
};

class PtxBadInput : public testing::TestWithParam<BadPtx> {};

TEST_P(PtxBadInput, IsRefusedWithFileLineAndProblem) {
  const BadPtx& bad = GetParam();
  const std::filesystem::path path = fixture(std::string("bad/") + bad.file);
  try {
    read_ptx(path);
    FAIL() << bad.file << " was accepted";
  } catch (const core::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(bad.file), std::string::npos) << message;
    EXPECT_NE(message.find(bad.problem), std::string::npos) << message;
    EXPECT_EQ(e.position().line.has_value(), bad.has_line) << message;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, PtxBadInput,
    testing::Values(BadPtx{"ptx_empty.ptx", "empty", true},
                    BadPtx{"ptx_blank_only.ptx", "no scan", true},
                    BadPtx{"ptx_truncated_body.ptx", "truncated", true},
                    BadPtx{"ptx_truncated_header.ptx", "ends inside the header", true},
                    BadPtx{"ptx_dims_exceed_file.ptx", "cannot fit", true},
                    BadPtx{"ptx_dims_overflow.ptx", "an integer", true},
                    BadPtx{"ptx_dims_too_many_points.ptx", "exceeds 2^31", true},
                    BadPtx{"ptx_dims_negative.ptx", "out of range", true},
                    BadPtx{"ptx_dims_not_integer.ptx", "an integer", true},
                    BadPtx{"ptx_extra_points.ptx", "more points than its header", true},
                    BadPtx{"ptx_non_numeric.ptx", "non-numeric", true},
                    BadPtx{"ptx_nan_field.ptx", "NaN", true},
                    BadPtx{"ptx_inf_field.ptx", "infinite", true},
                    BadPtx{"ptx_nonrigid_transform.ptx", "not rigid", true},
                    BadPtx{"ptx_nan_transform.ptx", "NaN", true},
                    BadPtx{"ptx_reflection_transform.ptx", "reflection", true},
                    BadPtx{"ptx_bad_field_count.ptx", "4 (x y z intensity) or 7", true},
                    BadPtx{"ptx_mixed_field_count.ptx", "first has 4", true},
                    BadPtx{"ptx_color_out_of_range.ptx", "0 to 255", true},
                    BadPtx{"ptx_header_field_count.ptx", "needs 3 numbers", true},
                    BadPtx{"ptx_coordinate_beyond_float.ptx", "beyond 10^8 m", true},
                    BadPtx{"ptx_intensity_beyond_float.ptx", "does not fit a float", true}),
    [](const testing::TestParamInfo<BadPtx>& info) {
      std::string name = std::filesystem::path(info.param.file).stem().string();
      return name;
    });

TEST(PtxReader, MissingFileIsRefusedWithItsName) {
  ScratchDir dir;
  EXPECT_THROW(read_ptx(dir / "absent.ptx"), core::InputError);
}

TEST(PtxReader, TruncationIsReportedAtTheLastLine) {
  try {
    read_ptx(fixture("bad/ptx_truncated_body.ptx"));
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.position().line, 14u);  // 10 header lines + 4 point lines
    EXPECT_NE(std::string(e.what()).find("declares 6 points, found 4"), std::string::npos);
  }
}

}  // namespace
}  // namespace scanbench::acquisition
