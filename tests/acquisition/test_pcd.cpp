#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "acquisition/formats/pcd_reader.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::fixture;
using test::ScratchDir;

// The scan of a file that makes one.
Scan only_scan(std::vector<ImportedScan> scans) {
  EXPECT_EQ(scans.size(), 1u);
  return std::move(scans.at(0).scan);
}

const std::vector<Eigen::Vector3f>& directions(const Scan& scan) {
  return std::get<PerPixelDirections>(scan.angles).directions;
}

// The reader computes in double and stores float; so does the expectation.
Eigen::Vector3f unit(double x, double y, double z) {
  const Eigen::Vector3d p(x, y, z);
  return (p / p.norm()).cast<float>();
}

std::vector<std::uint8_t> rgb_of(const Scan& scan, std::size_t i) {
  return {scan.rgb[3 * i], scan.rgb[3 * i + 1], scan.rgb[3 * i + 2]};
}

TEST(PcdReader, ReadsHandWrittenOrganizedAsciiWithExactValues) {
  const Scan scan = only_scan(read_pcd(fixture("good/pcd/organized_ascii.pcd")));
  ASSERT_EQ(scan.rows, 3);
  ASSERT_EQ(scan.columns, 4);
  ASSERT_FALSE(scan.is_spherical());
  ASSERT_TRUE(check_consistency(scan).empty()) << check_consistency(scan);
  EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 1, 1, 0, 0, 1, 1, 1, 1, 1, 1}));
  EXPECT_EQ(scan.range_m, (std::vector<float>{1, 2, 3, 5, 0, 0, 3, 2, 0.5f, 0.5f, 10, 1}));
  EXPECT_EQ(directions(scan)[0], Eigen::Vector3f(1, 0, 0));
  EXPECT_EQ(directions(scan)[2], Eigen::Vector3f(0, 0, -1));
  EXPECT_EQ(directions(scan)[3], unit(3, 4, 0));
  EXPECT_EQ(directions(scan)[6], unit(1, 2, 2));
  EXPECT_EQ(directions(scan)[10], unit(6, 0, 8));
  // (row 1, col 0) is NaN and (row 1, col 1) is (0, 0, 0): no return, no direction.
  EXPECT_EQ(directions(scan)[scan.index(1, 0)], Eigen::Vector3f::Zero());
  EXPECT_EQ(directions(scan)[scan.index(1, 1)], Eigen::Vector3f::Zero());
  EXPECT_EQ(rgb_of(scan, 0), (std::vector<std::uint8_t>{255, 0, 0}));
  EXPECT_EQ(rgb_of(scan, 1), (std::vector<std::uint8_t>{0, 255, 0}));
  EXPECT_EQ(rgb_of(scan, 2), (std::vector<std::uint8_t>{0, 0, 255}));
  EXPECT_EQ(rgb_of(scan, 3), (std::vector<std::uint8_t>{10, 20, 30}));
  EXPECT_EQ(rgb_of(scan, 6), (std::vector<std::uint8_t>{16, 32, 48}));
  EXPECT_EQ(scan.intensity, (std::vector<float>{0.5f, 0.25f, 1, 0, 0, 0.75f, 0.125f, 1, 0.0625f,
                                                0.375f, 0.875f, 0.5f}));
}

TEST(PcdReader, AnUnorganizedCloudKeepsEveryReturnInItsOrder) {
  const Scan scan = only_scan(read_pcd(fixture("good/pcd/unorganized_ascii.pcd")));
  ASSERT_TRUE(scan.is_scattered());
  ASSERT_TRUE(check_consistency(scan).empty()) << check_consistency(scan);
  ASSERT_EQ(count_valid(scan), 10u) << "12 records, one NaN and one (0, 0, 0)";
  const auto point = [&](std::size_t k) {
    return point_in_world(scan, static_cast<int>(k) / scan.columns,
                          static_cast<int>(k) % scan.columns);
  };
  EXPECT_LT((point(0) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-6);
  EXPECT_LT((point(3) - Eigen::Vector3d(3, 4, 0)).norm(), 1e-6);
  EXPECT_LT((point(4) - Eigen::Vector3d(1, 2, 2)).norm(), 1e-6) << "the 7th record, 5th return";
  EXPECT_EQ(rgb_of(scan, 3), (std::vector<std::uint8_t>{10, 20, 30}));
  EXPECT_EQ(scan.intensity[4], 0.125f);
}

TEST(PcdReader, AnUnorganizedCloudTooWideForOneScanIsTiled) {
  // Doubles 5 km apart: one scan would put the far ones 0.15 mm off.
  const ScratchDir dir;
  const std::filesystem::path path = dir / "wide.pcd";
  std::ofstream(path) << "VERSION 0.7\nFIELDS x y z intensity\nSIZE 8 8 8 4\nTYPE F F F F\n"
                         "COUNT 1 1 1 1\nWIDTH 4\nHEIGHT 1\nPOINTS 4\n"
                         "VIEWPOINT 10 0 0 1 0 0 0\nDATA ascii\n"
                         "1.0001 2 3 0.5\n3000.0003 4000 3 0.25\n1 2.5 3.0002 1\n"
                         "3001.25 4000.0001 3 0\n";
  const std::vector<ImportedScan> scans = read_pcd(path);
  ASSERT_EQ(scans.size(), 2u);
  const Eigen::Vector3d expected[2][2] = {{{11.0001, 2, 3}, {11, 2.5, 3.0002}},
                                          {{3010.0003, 4000, 3}, {3011.25, 4000.0001, 3}}};
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_EQ(scans[s].scan.name, "wide-" + std::to_string(s + 1));
    EXPECT_EQ(scans[s].source.format, "pcd");
    EXPECT_EQ(scans[s].source.points_in_file, 2u);
    ASSERT_EQ(count_valid(scans[s].scan), 2u);
    for (int k = 0; k < 2; ++k) {
      EXPECT_LT((point_in_world(scans[s].scan, 0, k) - expected[s][k]).norm(), 1e-4) << s << k;
    }
  }
  EXPECT_EQ(scans[1].scan.intensity[1], 0.0f);
  EXPECT_EQ(scans[0].scan.intensity[1], 1.0f);
}

TEST(PcdReader, AnUnorganizedCloudWithoutAReturnIsRefused) {
  const ScratchDir dir;
  const std::filesystem::path path = dir / "nothing.pcd";
  std::ofstream(path) << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                         "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\nnan nan nan\n0 0 0\n";
  EXPECT_THAT([&] { read_pcd(path); },
              ::testing::ThrowsMessage<core::InputError>(
                  ::testing::HasSubstr("no point with a return: there is nothing to import")));
}

TEST(PcdReader, TakesPoseFromViewpointAndNameFromStem) {
  const Scan scan = only_scan(read_pcd(fixture("good/pcd/organized_ascii.pcd")));
  // VIEWPOINT 1 2 3 0.70710678 0 0 0.70710678: 90 degrees about z.
  EXPECT_EQ(scan.T_world_scan.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE((scan.T_world_scan.linear() * Eigen::Vector3d::UnitX())
                  .isApprox(Eigen::Vector3d::UnitY(), 1e-7));
  EXPECT_EQ(scan.scanner.position_world, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(scan.scanner.name, "");
  EXPECT_EQ(scan.name, "organized_ascii");
  EXPECT_NE(scan.scanner.source_file.find("organized_ascii.pcd"), std::string::npos);
}

// organized_binary.pcd was written by PCL from a 3 x 2 PointXYZRGB cloud:
// points (1,0,0) (0,-2,0) NaN / (0,0,4) (3,0,4) (0,0,0), colors
// (40i+5, 250-30i, 17i), origin (0.5, -1, 2), 180 degrees about x.
void expect_pcl_written_cloud(const Scan& scan) {
  ASSERT_EQ(scan.rows, 2);
  ASSERT_EQ(scan.columns, 3);
  EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 0, 1, 1, 0}));
  EXPECT_EQ(scan.range_m, (std::vector<float>{1, 2, 0, 4, 5, 0}));
  EXPECT_EQ(directions(scan)[1], Eigen::Vector3f(0, -1, 0));
  EXPECT_EQ(directions(scan)[4], unit(3, 0, 4));
  EXPECT_EQ(directions(scan)[2], Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(rgb_of(scan, i), (std::vector<std::uint8_t>{static_cast<std::uint8_t>(40 * i + 5),
                                                          static_cast<std::uint8_t>(250 - 30 * i),
                                                          static_cast<std::uint8_t>(17 * i)}));
  }
  EXPECT_FALSE(scan.has_intensity());
  Eigen::Matrix4d pose;
  pose << 1, 0, 0, 0.5, 0, -1, 0, -1, 0, 0, -1, 2, 0, 0, 0, 1;
  EXPECT_EQ(scan.T_world_scan.matrix(), pose);
}

TEST(PcdReader, ReadsBinaryWrittenByPcl) {
  expect_pcl_written_cloud(only_scan(read_pcd(fixture("good/pcd/organized_binary.pcd"))));
}

TEST(PcdReader, ReadsBinaryCompressedWrittenByPcl) {
  expect_pcl_written_cloud(only_scan(read_pcd(fixture("good/pcd/organized_compressed.pcd"))));
}

TEST(PcdReader, ReadsPathWithSpacesAndNonAscii) {
  const ScratchDir dir;  // its name already holds a space and an é
  const auto copy = dir / "capture ü 1.pcd";
  std::filesystem::copy_file(fixture("good/pcd/organized_binary.pcd"), copy);
  const Scan scan = only_scan(read_pcd(copy));
  EXPECT_EQ(scan.name, "capture ü 1");
  expect_pcl_written_cloud(scan);
}

TEST(PcdReader, MissingFileIsAnInputError) {
  const ScratchDir dir;
  EXPECT_THROW(read_pcd(dir / "absent.pcd"), core::InputError);
}

TEST(PcdReader, NonNumericValueReportsItsLine) {
  try {
    read_pcd(fixture("bad/pcd_non_numeric.pcd"));
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    ASSERT_TRUE(e.position().line.has_value()) << e.what();
    EXPECT_EQ(*e.position().line, 17u) << e.what();
  }
}

// A compressed body whose size word claims 4 GB must be refused before the reader
// allocates for it.
TEST(PcdReader, RefusesCompressedBodyWhoseSizeWordLies) {
  const ScratchDir dir;
  std::string bytes = test::read_file_bytes(fixture("good/pcd/organized_compressed.pcd"));
  const std::string data_line = "DATA binary_compressed\n";
  const std::size_t body = bytes.find(data_line) + data_line.size();
  ASSERT_LT(body + 8, bytes.size());
  std::memset(&bytes[body + 4], 0xff, 4);  // uncompressed size
  const auto path = dir / "lying.pcd";
  std::ofstream(path, std::ios::binary) << bytes;
  try {
    read_pcd(path);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(e.problem().find("disagrees"), std::string::npos) << e.what();
  }
}

// A compressed body whose LZF runs are damaged (a back reference before the
// start) is refused, never followed out of the buffer.
TEST(PcdReader, RefusesADamagedCompressedBody) {
  const ScratchDir dir;
  std::string bytes = test::read_file_bytes(fixture("good/pcd/organized_compressed.pcd"));
  const std::string data_line = "DATA binary_compressed\n";
  const std::size_t body = bytes.find(data_line) + data_line.size();
  ASSERT_LT(body + 10, bytes.size());
  bytes[body + 8] = static_cast<char>(0xff);  // first run: a back reference 8 KB back
  bytes[body + 9] = static_cast<char>(0xff);
  const auto path = dir / "damaged.pcd";
  std::ofstream(path, std::ios::binary) << bytes;
  try {
    read_pcd(path);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(e.problem().find("damaged compressed body"), std::string::npos) << e.what();
  }
}

// Coordinates at 10^6–10^7 m stored as doubles keep 0.1 mm: the scan frame
// moves near the points.
TEST(PcdReader, WorldCoordinatesKeepATenthOfAMillimetre) {
  const std::filesystem::path path = fixture("good/pcd/world_utm_double.pcd");
  const Scan scan = only_scan(read_pcd(path));
  std::ifstream in(path);
  std::string line;
  for (int k = 0; k < 11; ++k) std::getline(in, line);
  double worst = 0.0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      Eigen::Vector3d expected;
      int intensity = 0;
      in >> expected.x() >> expected.y() >> expected.z() >> intensity;
      worst = std::max(worst, (point_in_world(scan, row, col) - expected).norm());
      EXPECT_EQ(scan.intensity[scan.index(row, col)], static_cast<float>(intensity));
    }
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(scan.T_world_scan.translation().norm(), 8e6);  // the offset is in the pose
}

// A sparse file whose header declares 2147 x 1,000,000 binary points (25.8
// GB of body) passes the size checks; it must be refused for the memory it
// needs (129 GB with the scan), not die in std::bad_alloc.
TEST(PcdReader, AHeaderAskingForMoreMemoryThanThereIsIsRefused) {
  const ScratchDir dir;
  const auto path = dir / "sparse.pcd";
  const std::string header =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1000000\n"
      "HEIGHT 2147\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2147000000\nDATA binary\n";
  { std::ofstream(path, std::ios::binary) << header; }
  std::error_code error;
  std::filesystem::resize_file(path, header.size() + std::uint64_t{2147000000} * 12, error);
  const std::optional<std::uint64_t> available = core::available_memory_bytes();
  if (error || !available || *available > std::uint64_t{129} << 30) {
    GTEST_SKIP() << "needs a sparse file and less than 129 GB of free memory";
  }
  try {
    read_pcd(path);
    FAIL() << "expected core::RuntimeFailure";
  } catch (const core::RuntimeFailure& e) {
    EXPECT_NE(std::string(e.what()).find("GB of memory"), std::string::npos) << e.what();
  }
}

struct BadPcd {
  const char* fixture;  // fixtures/bad/<fixture>.pcd
  const char* problem;  // word(s) describing the problem
};

class PcdBadInput : public testing::TestWithParam<BadPcd> {};

TEST_P(PcdBadInput, ThrowsInputErrorNamingFileAndProblem) {
  const BadPcd& c = GetParam();
  const std::string name = std::string(c.fixture) + ".pcd";
  try {
    read_pcd(fixture("bad/" + name));
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find(c.problem), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, PcdBadInput,
    testing::Values(BadPcd{"pcd_empty", "empty file"}, BadPcd{"pcd_not_pcd", "not a PCD file"},
                    BadPcd{"pcd_empty_cloud", "empty point cloud"},
                    BadPcd{"pcd_missing_xyz", "missing field z"},
                    BadPcd{"pcd_truncated_ascii", "truncated ASCII body"},
                    BadPcd{"pcd_truncated_binary", "truncated binary body"},
                    BadPcd{"pcd_truncated_compressed", "truncated compressed body"},
                    BadPcd{"pcd_non_numeric", "'abc' is not a number"},
                    BadPcd{"pcd_value_out_of_type", "'70000' is not a number of the field's type"},
                    BadPcd{"pcd_coordinate_beyond_range",
                           "point 3 (row 0, col 3): coordinate beyond 10^8 m"},
                    BadPcd{"pcd_wrong_value_count", "4 values, the header says 5"},
                    BadPcd{"pcd_extra_points", "more points"},
                    BadPcd{"pcd_points_mismatch", "disagrees with POINTS"},
                    BadPcd{"pcd_absurd_width", "absurd dimensions"},
                    BadPcd{"pcd_unknown_data_type", "unknown DATA type"},
                    BadPcd{"pcd_viewpoint_nan", "VIEWPOINT has a non-finite value"},
                    BadPcd{"pcd_viewpoint_garbage", "'zero' is not a number"},
                    BadPcd{"pcd_viewpoint_short", "VIEWPOINT needs 7 numbers"},
                    BadPcd{"pcd_viewpoint_non_unit", "quaternion is not unit"}),
    [](const testing::TestParamInfo<BadPcd>& info) {
      return std::string(info.param.fixture).substr(std::strlen("pcd_"));
    });

}  // namespace
}  // namespace scanbench::acquisition
