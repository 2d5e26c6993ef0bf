// E57 (ASTM E2807): the checksum and the bit packing against values worked
// out by hand or by a reference bit writer of the test's own; the fixtures
// of fixtures/good/e57, written by an independent writer
// (fixtures/generate_e57_fixtures.py), read back to the values it wrote;
// every class of bad input; and scans written by write_e57 read back whole.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <random>

#include "acquisition/formats/e57/crc32c.hpp"
#include "acquisition/formats/e57/e57_bitpack.hpp"
#include "acquisition/formats/e57/e57_reader.hpp"
#include "acquisition/formats/e57/e57_writer.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::ScratchDir;

std::vector<ImportedScan> read_all(const std::filesystem::path& path,
                                   std::vector<ScanImage>* loose = nullptr) {
  std::vector<ImportedScan> scans;
  read_e57(
      path, [&scans](ImportedScan&& scan) { scans.push_back(std::move(scan)); },
      [loose](ScanImage&& image) {
        if (loose != nullptr) loose->push_back(std::move(image));
      });
  return scans;
}

// ---- Checksum -----------------------------------------------------------

TEST(Crc32c, GivesTheCheckValuesOfCastagnoli) {
  const std::string check = "123456789";
  EXPECT_EQ(crc32c(std::as_bytes(std::span(check))), 0xE3069283u);
  const std::vector<std::byte> zeros(1020, std::byte{0});
  EXPECT_EQ(crc32c(zeros), 0xB641CDE2u);  // stored as B6 41 CD E2 after a page of zeros
}

TEST(Crc32c, HardwareAndPortablePathsAgree) {
  std::mt19937 random(3);
  for (std::size_t size : {0u, 1u, 7u, 8u, 9u, 1020u, 4099u}) {
    std::vector<std::byte> bytes(size);
    for (std::byte& b : bytes) b = static_cast<std::byte>(random());
    EXPECT_EQ(crc32c(bytes), crc32c_portable(bytes)) << size;
  }
}

// ---- Bit packing ----------------------------------------------------------

// The reference: each value's bits, least significant first, one by one.
std::vector<std::byte> reference_pack(const std::vector<std::uint64_t>& raw, int bits) {
  std::vector<std::byte> out;
  std::uint64_t position = 0;
  for (const std::uint64_t value : raw) {
    for (int b = 0; b < bits; ++b, ++position) {
      if (position % 8 == 0) out.push_back(std::byte{0});
      if ((value >> b) & 1u) out.back() |= static_cast<std::byte>(1u << (position % 8));
    }
  }
  return out;
}

class IntegerWidth : public ::testing::TestWithParam<int> {};

TEST_P(IntegerWidth, PacksAsTheReferenceAndUnpacksToTheSameValues) {
  const int bits = GetParam();
  E57Field field;
  field.name = "value";
  field.type = E57FieldType::kInteger;
  // A negative minimum (odd where a double holds every value), and a span
  // of exactly `bits` bits.
  field.minimum = bits == 64   ? std::numeric_limits<std::int64_t>::min()
                  : bits <= 53 ? -(std::int64_t{1} << (bits - 1)) + 3
                               : -(std::int64_t{1} << (bits - 1));
  field.maximum = bits == 64
                      ? std::numeric_limits<std::int64_t>::max()
                      : field.minimum + static_cast<std::int64_t>((std::uint64_t{1} << bits) - 1);
  ASSERT_EQ(field.bits(), bits);
  std::mt19937_64 random(static_cast<unsigned>(bits));
  // Values a double holds exactly: beyond 53 bits, multiples of 2^(bits − 53).
  const int drop = std::max(0, bits - 53);
  std::vector<std::uint64_t> raw(37);
  std::vector<double> values(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    raw[i] = (bits == 64 ? random() : random() % (std::uint64_t{1} << bits)) >> drop << drop;
    if (i == 0) raw[i] = 0;
    values[i] = static_cast<double>(
        static_cast<std::int64_t>(static_cast<std::uint64_t>(field.minimum) + raw[i]));
  }
  std::vector<std::byte> packed;
  e57_pack(field, values, packed);
  EXPECT_EQ(packed, reference_pack(raw, bits));
  EXPECT_EQ(packed.size(), e57_stream_bytes(field, raw.size()));
  std::vector<double> unpacked(values.size());
  ASSERT_TRUE(e57_unpack(field, packed, 0, unpacked));
  EXPECT_EQ(unpacked, values);
  std::vector<double> middle(7);
  ASSERT_TRUE(e57_unpack(field, packed, 5, middle)) << "records 5 to 11, mid-byte";
  EXPECT_EQ(middle, std::vector<double>(values.begin() + 5, values.begin() + 12));
  packed.pop_back();
  EXPECT_FALSE(e57_unpack(field, packed, 0, unpacked)) << "a short stream is refused";
}

INSTANTIATE_TEST_SUITE_P(EveryWidth, IntegerWidth, ::testing::Range(1, 65));

TEST(ScaledInteger, StoresRoundedRawValuesAndScalesThemBack) {
  E57Field field;
  field.type = E57FieldType::kScaledInteger;
  field.minimum = -5;
  field.maximum = 1000;  // 10 bits
  field.scale = 0.001;
  field.offset = 5412000.0;
  const std::vector<double> values = {5412000.0, 5412000.2504, 5411999.995, 5412001.0, 5413000.0};
  std::vector<std::byte> packed;
  e57_pack(field, values, packed);
  std::vector<double> back(values.size());
  ASSERT_TRUE(e57_unpack(field, packed, 0, back));
  const std::vector<double> expected = {5412000.0, 5412000.25, 5411999.995, 5412001.0, 5412001.0};
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_NEAR(back[i], expected[i], 1e-9) << i;
  EXPECT_EQ(reference_pack({5, 255, 0, 1005, 1005}, 10), packed) << "raw − minimum, clamped";
}

TEST(ZeroWidth, TakesNoBytesAndGivesTheMinimum) {
  E57Field field;
  field.type = E57FieldType::kInteger;
  field.minimum = field.maximum = 7;
  std::vector<std::byte> packed;
  e57_pack(field, std::vector<double>(100, 7.0), packed);
  EXPECT_TRUE(packed.empty());
  std::vector<double> values(100);
  ASSERT_TRUE(e57_unpack(field, {}, 0, values));
  EXPECT_THAT(values, ::testing::Each(7.0));
}

TEST(Float, StoresLittleEndianIeeeNumbersOfEitherPrecision) {
  for (const bool single : {true, false}) {
    E57Field field;
    field.type = E57FieldType::kFloat;
    field.single_precision = single;
    const std::vector<double> values = {1.5, -0.25, 1e30, 3.0};
    std::vector<std::byte> packed;
    e57_pack(field, values, packed);
    ASSERT_EQ(packed.size(), values.size() * (single ? 4u : 8u));
    // 1.5 is 0x3FC00000 (single) or 0x3FF8000000000000 (double): its last byte first.
    EXPECT_EQ(packed[single ? 3 : 7], std::byte{0x3F});
    std::vector<double> back(values.size());
    ASSERT_TRUE(e57_unpack(field, packed, 0, back));
    for (std::size_t i = 0; i < values.size(); ++i) {
      EXPECT_EQ(back[i], single ? static_cast<double>(static_cast<float>(values[i])) : values[i]);
    }
  }
}

// ---- The independent writer's fixtures ------------------------------------

TEST(E57Fixture, StructuredSphericalScanKeepsItsGridValuesPoseAndImages) {
  std::vector<ScanImage> loose;
  const std::vector<ImportedScan> scans =
      read_all(test::fixture("good/e57/structured_spherical.e57"), &loose);
  ASSERT_EQ(scans.size(), 2u) << "the grid, and the record it has no pixel for";
  const Scan& scan = scans[0].scan;
  ASSERT_EQ(scan.rows, 5);
  ASSERT_EQ(scan.columns, 7);
  EXPECT_TRUE(scan.is_spherical());
  EXPECT_EQ(scan.name, "structured");
  EXPECT_EQ(scans[0].source.format, "e57");
  EXPECT_EQ(scans[0].source.guid, "{scan-structured}");
  EXPECT_EQ(scans[0].source.points_in_file, 36u);
  EXPECT_EQ(scans[0].source.unplaced_points, 1u) << "the second return of pixel (2, 3)";
  const Eigen::Isometry3d pose =
      Eigen::Translation3d(100.0, 200.0, 10.0) *
      Eigen::AngleAxisd(30.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ());
  for (int r = 0; r < 5; ++r) {
    for (int c = 0; c < 7; ++c) {
      const std::size_t i = scan.index(r, c);
      const bool broken = (r == 1 && c == 2) || (r == 3 && c == 4);
      ASSERT_EQ(scan.valid[i] != 0, !broken) << r << "," << c;
      if (broken) continue;
      const double range = 5.0 + 0.1 * r + 0.05 * c;
      const double az = 0.3 + 0.02 * c;
      const double el = static_cast<float>(0.2 - 0.015 * r);  // stored single
      const Eigen::Vector3d expected =
          pose * (range * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                          std::sin(el)));
      EXPECT_LT((point_in_world(scan, r, c) - expected).norm(), 1e-4) << r << "," << c;
      EXPECT_FLOAT_EQ(scan.intensity[i], static_cast<float>((r * 7 + c) * 100) / 4095.0f);
      EXPECT_EQ(scan.rgb[3 * i], 10 * c);
      EXPECT_EQ(scan.rgb[3 * i + 1], std::lround(255.0 * 100 * r / 1023.0));
      EXPECT_EQ(scan.rgb[3 * i + 2], std::lround(255.0 * 1000 * (r + c) / 65535.0));
    }
  }
  ASSERT_EQ(scans[0].images.size(), 1u);
  const ScanImage& camera = scans[0].images[0];
  EXPECT_EQ(camera.name, "camera 1");
  EXPECT_EQ(camera.guid, "{image-pinhole}");
  EXPECT_EQ(camera.projection, ImageProjection::kPinhole);
  EXPECT_EQ(camera.format, "png");
  EXPECT_EQ(camera.width, 4);
  EXPECT_EQ(camera.height, 3);
  EXPECT_DOUBLE_EQ(camera.focal_length, 0.01);
  EXPECT_DOUBLE_EQ(camera.principal_y, 1.5);
  EXPECT_DOUBLE_EQ(camera.T_world_image.translation().z(), 10.5);
  ASSERT_GE(camera.data.size(), 8u);
  EXPECT_EQ(camera.data[1], 'P');
  ASSERT_EQ(loose.size(), 1u);
  EXPECT_EQ(loose[0].format, "jpeg");
  EXPECT_EQ(loose[0].projection, ImageProjection::kSpherical);
  EXPECT_EQ(loose[0].data.size(), 662u);
  EXPECT_EQ(loose[0].data[0], 0xFF);
  EXPECT_EQ(loose[0].data[1], 0xD8);

  // The second return of pixel (2, 3), kept beside the grid.
  const ImportedScan& unplaced = scans[1];
  ASSERT_TRUE(unplaced.scan.is_scattered());
  EXPECT_EQ(count_valid(unplaced.scan), 1u);
  EXPECT_EQ(unplaced.scan.name, "structured-unplaced");
  EXPECT_EQ(unplaced.source.guid, "{scan-structured}-unplaced");
  EXPECT_EQ(unplaced.source.points_in_file, 1u);
  EXPECT_EQ(unplaced.source.unplaced_points, 0u);
  EXPECT_TRUE(unplaced.images.empty());
  const double az = 0.3 + 0.02 * 3, el = static_cast<float>(0.2 - 0.015 * 2);
  const Eigen::Vector3d second =
      pose * (9.0 * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                    std::sin(el)));
  EXPECT_LT((point_in_world(unplaced.scan, 0, 0) - second).norm(), 1e-4);
  EXPECT_FLOAT_EQ(unplaced.scan.intensity[0], static_cast<float>((2 * 7 + 3) * 100) / 4095.0f);
  EXPECT_EQ(unplaced.scan.rgb[0], 30);
}

// The points fixtures/generate_e57_fixtures.py puts in the unstructured
// scan, as the file holds them (mm steps), each `scale` times as far.
std::vector<Eigen::Vector3d> unstructured_points(double scale = 1.0) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 30; ++j) {
      const double az = -0.5 + 0.01 * j, el = -0.1 + 0.01 * i, range = 8.0 + 0.01 * j;
      const Eigen::Vector3d p(range * std::cos(el) * std::cos(az),
                              range * std::cos(el) * std::sin(az), range * std::sin(el));
      points.push_back((scale * p / 0.001).array().round().matrix() * 0.001);
    }
  }
  return points;
}

TEST(E57Fixture, AnUnstructuredScanTooWideForOneIsTiledWithinATenthOfAMillimetre) {
  const std::vector<ImportedScan> scans = read_all(test::fixture("good/e57/unstructured_wide.e57"));
  ASSERT_EQ(scans.size(), 2u) << "one scan per 400 m cube";
  for (std::size_t s = 0; s < 2; ++s) {
    const ImportedScan& tile = scans[s];
    EXPECT_EQ(tile.scan.name, "wide-" + std::to_string(s + 1));
    EXPECT_EQ(tile.source.guid, "{scan-wide}-" + std::to_string(s + 1));
    EXPECT_EQ(tile.source.points_in_file, 100u);
    ASSERT_EQ(count_valid(tile.scan), 100u);
    EXPECT_LE(tile.scan.import_round_trip_m, kPromisedRoundTripM);
    for (int j = 0; j < 100; ++j) {  // the fixture's record 2j + s, in the file's order
      const int k = 2 * j + static_cast<int>(s);
      const Eigen::Vector3d expected(3000.0 * s + 0.25 * (k % 10), 4000.0 * s + 0.5 * (k / 20),
                                     1.0 + 0.001 * k);
      EXPECT_LT((point_in_world(tile.scan, j / tile.scan.columns, j % tile.scan.columns) - expected)
                    .norm(),
                1e-4)
          << s << " " << j;
    }
  }
}

TEST(E57Fixture, AnUnstructuredScanKeepsEveryPointWithAReturn) {
  const std::vector<ImportedScan> scans =
      read_all(test::fixture("good/e57/unstructured_cartesian.e57"));
  ASSERT_EQ(scans.size(), 1u);
  const Scan& scan = scans[0].scan;
  EXPECT_TRUE(scan.is_scattered());
  EXPECT_EQ(check_consistency(scan), "");
  EXPECT_EQ(scans[0].source.points_in_file, 605u);
  EXPECT_EQ(scans[0].source.unplaced_points, 0u);
  EXPECT_EQ(count_valid(scan), 602u) << "all but the three records without a return";
  // The 600 points and the two behind two of them, each within 0.1 mm of
  // the file's value, each exactly once.
  std::vector<Eigen::Vector3d> expected = unstructured_points();
  std::vector<float> intensity;
  for (int k = 0; k < 600; ++k) intensity.push_back(static_cast<float>(k / 600.0));
  for (const int behind : {45, 301}) {
    expected.push_back(unstructured_points(2.0)[behind]);
    intensity.push_back(intensity[behind]);
  }
  std::vector<int> seen(expected.size(), 0);
  for (std::size_t p = 0; p < count_valid(scan); ++p) {
    const int r = static_cast<int>(p) / scan.columns, c = static_cast<int>(p) % scan.columns;
    const Eigen::Vector3d point = point_in_world(scan, r, c);
    std::size_t best = 0;
    for (std::size_t k = 1; k < expected.size(); ++k) {
      if ((expected[k] - point).norm() < (expected[best] - point).norm()) best = k;
    }
    EXPECT_LT((expected[best] - point).norm(), 1e-4);
    EXPECT_NEAR(scan.intensity[p], intensity[best], 1e-6);
    ++seen[best];
  }
  EXPECT_THAT(seen, ::testing::Each(1));
}

// fixtures/generate_e57_fixtures.py's sphere: 4 000 points of a closed
// surface seen from outside, in file order.
Eigen::Vector3d sphere_point(int k) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - 2.0 * (k + 0.5) / 4000.0, r = std::sqrt(1.0 - z * z);
  return Eigen::Vector3d(4.0 + r * std::cos(golden * k), 1.0 + r * std::sin(golden * k), 0.5 + z);
}

TEST(E57Fixture, AClosedObjectKeepsThePointsAPanoramaWouldHide) {
  const std::vector<ImportedScan> scans =
      read_all(test::fixture("good/e57/unstructured_sphere.e57"));
  ASSERT_EQ(scans.size(), 1u);
  const Scan& scan = scans[0].scan;
  ASSERT_TRUE(scan.is_scattered());
  ASSERT_EQ(count_valid(scan), 4000u);
  // The file's order, each point as the file gives it (0.1 mm steps).
  double worst = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const Eigen::Vector3d p = point_in_world(scan, k / scan.columns, k % scan.columns);
    worst = std::max(worst, (p - sphere_point(k)).norm());
  }
  EXPECT_LT(worst, 1e-4);
  // Its far side lies behind its near side: seen from the origin, about
  // half the sphere is hidden, the cloud's points that a panorama drops.
  int hidden = 0;
  const Eigen::Vector3d centre(4.0, 1.0, 0.5);
  for (int k = 0; k < 4000; ++k) {
    const Eigen::Vector3d p = sphere_point(k);
    hidden += (p - centre).dot(p) > 0.0;
  }
  EXPECT_GT(hidden, 1000) << "at least a quarter of the points would collide";
}

TEST(E57Fixture, GeoreferencedCoordinatesKeepATenthOfAMillimetre) {
  const std::vector<ImportedScan> scans = read_all(test::fixture("good/e57/georeferenced.e57"));
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].source.coordinate_metadata, "EPSG:25832");
  const Eigen::Vector3d base(512345.6789, 5412345.4321, 312.25);
  const Scan& utm = scans[0].scan;
  ASSERT_EQ(utm.rows, 4);
  ASSERT_EQ(utm.columns, 6);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 6; ++c) {
      const double az = 0.1 * c, el = 0.05 * r, range = 30.0 + r + 0.5 * c;
      const Eigen::Vector3d expected =
          base + range * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                         std::sin(el));
      EXPECT_LT((point_in_world(utm, r, c) - expected).norm(), 1e-4) << r << "," << c;
    }
  }
  const Scan& posed = scans[1].scan;
  const Eigen::Vector3d translation(9876543.21, 1234567.89, 250.0);
  EXPECT_EQ(posed.T_world_scan.translation(), translation);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      const double az = -1.0 + 0.01 * c, el = 0.02 * r, range = 20.0 + 0.25 * r + 0.5 * c;
      const Eigen::Vector3d expected =
          translation + range * Eigen::Vector3d(std::cos(el) * std::cos(az),
                                                std::cos(el) * std::sin(az), std::sin(el));
      EXPECT_LT((point_in_world(posed, r, c) - expected).norm(), 1e-4) << r << "," << c;
    }
  }
}

// ---- Bad input --------------------------------------------------------------

struct BadCase {
  const char* file;
  const char* message;
};

class BadE57 : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadE57, IsRefusedNamingWhereAndWhy) {
  const auto path = test::fixture(std::string("bad/") + GetParam().file);
  try {
    read_all(path);
    FAIL() << "accepted " << GetParam().file;
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_THAT(e.what(), ::testing::HasSubstr(GetParam().message));
  }
}

INSTANTIATE_TEST_SUITE_P(
    EveryClass, BadE57,
    ::testing::Values(
        BadCase{"e57_bad_signature.e57", "signature is not \"ASTM-E57\""},
        BadCase{"e57_bad_checksum.e57",
                "(byte 1024), page 1: page fails its CRC-32C checksum (the file is damaged), in "
                "the points of /data3D/0"},
        BadCase{"e57_malformed_xml.e57", "malformed XML"},
        BadCase{"e57_truncated_file.e57",
                "the header gives a length of 9216 bytes but the file "
                "has 8192"},
        BadCase{"e57_prototype_mismatch.e57", "packet of 5 bytestreams where the prototype has 6"},
        BadCase{"e57_truncated_section.e57", "fewer bytes of field \"cartesianX\""},
        BadCase{"e57_no_coordinates.e57", "neither cartesianX/Y/Z nor sphericalRange"},
        BadCase{"e57_index_outside_bounds.e57", "outside the scan's index bounds"},
        BadCase{"e57_float_index.e57", "rowIndex: is not an Integer field"},
        BadCase{"e57_image_size.e57", "has an image of 0 × 3 pixels"},
        BadCase{"e57_deep_prototype.e57", "nests structures deeper than scanbench reads"},
        BadCase{"e57_short_packet.e57", "data packet too short for its header"},
        BadCase{"e57_repeated_images.e57", "each image needs a blob of its own"},
        BadCase{"e57_image_offset_in_checksum.e57", "inside a page checksum"},
        BadCase{"e57_section_beyond_file.e57", "beyond the end of the file"},
        BadCase{"e57_no_scan.e57", "/data3D: holds no scan"},
        BadCase{"e57_no_records.e57", "/data3D/0/points: holds no point records"}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
      std::string name = info.param.file;
      name = name.substr(4, name.size() - 8);
      return name;
    });

TEST(E57Fixture, AbsurdCoordinatesAndStatesAreNoReturns) {
  const std::vector<ImportedScan> scans = read_all(test::fixture("good/e57/absurd_values.e57"));
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(count_valid(scans[0].scan), 2u) << "10^300 m and a NaN state are no points";
  EXPECT_EQ(scans[0].source.points_in_file, 4u);
}

TEST(BadE57, AFileOfNoWholePagesIsRefused) {
  const ScratchDir dir;
  const auto path = dir.path() / "short.e57";
  std::ofstream(path, std::ios::binary) << "ASTM-E57 and not much more";
  EXPECT_THROW(read_all(path), core::InputError);
}

// ---- write_e57 read back --------------------------------------------------------

// A 30 × 50 panorama with gaps, intensity and colour, at `pose`.
Scan panorama(const Eigen::Isometry3d& pose) {
  constexpr int kRows = 30, kColumns = 50;
  Scan scan = make_empty_scan(kRows, kColumns, true, true);
  scan.name = "panorama";
  scan.scanner.name = "virtual";
  scan.angles = SphericalAngles{-1.0, 0.004, 0.3, -0.005};
  scan.T_world_scan = pose;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kColumns; ++c) {
      const std::size_t i = scan.index(r, c);
      if ((r * 5 + c) % 9 == 0) continue;
      scan.valid[i] = 1;
      scan.range_m[i] = 12.0f + 0.37f * static_cast<float>(r) + 0.011f * static_cast<float>(c);
      scan.intensity[i] = static_cast<float>((r + c) % 17) / 16.0f;
      scan.rgb[3 * i] = static_cast<std::uint8_t>(r * 8);
      scan.rgb[3 * i + 1] = static_cast<std::uint8_t>(c * 5);
      scan.rgb[3 * i + 2] = static_cast<std::uint8_t>(255 - r);
    }
  }
  return scan;
}

void expect_same_scan(const Scan& written, const Scan& read) {
  ASSERT_EQ(read.rows, written.rows);
  ASSERT_EQ(read.columns, written.columns);
  EXPECT_EQ(read.valid, written.valid);
  EXPECT_EQ(read.rgb, written.rgb);
  EXPECT_EQ(read.intensity, written.intensity);
  EXPECT_EQ(read.is_spherical(), written.is_spherical());
  double worst = 0.0;
  for (int r = 0; r < read.rows; ++r) {
    for (int c = 0; c < read.columns; ++c) {
      if (!read.valid[read.index(r, c)]) continue;
      worst = std::max(worst, (point_in_world(read, r, c) - point_in_world(written, r, c)).norm());
    }
  }
  EXPECT_LT(worst, 1e-4) << "every point within 0.1 mm";
}

TEST(WriteE57, ScansComeBackWithGridValidityValuesPoseAndImages) {
  const ScratchDir dir;
  const Eigen::Isometry3d georeferenced =
      Eigen::Translation3d(9876543.21, 5412345.43, 312.5) *
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.1, 0.2, 1.0).normalized());
  Scan spherical = panorama(georeferenced);
  spherical.name = "hall ]]> & <north> é";  // CDATA's end, markup and UTF-8
  // The same scan with an irregular direction per pixel, some unknown.
  Scan per_pixel = panorama(Eigen::Isometry3d(Eigen::Translation3d(10.0, -4.0, 1.0)));
  PerPixelDirections directions;
  std::mt19937 random(5);
  std::uniform_real_distribution<float> jitter(-1e-3f, 1e-3f);
  for (int r = 0; r < per_pixel.rows; ++r) {
    for (int c = 0; c < per_pixel.columns; ++c) {
      const bool unknown = !per_pixel.valid[per_pixel.index(r, c)] && c % 2 == 0;
      const Eigen::Vector3f d =
          (direction(spherical, r, c) + Eigen::Vector3f(jitter(random), jitter(random), 0.0f))
              .normalized();
      directions.directions.push_back(unknown ? Eigen::Vector3f(Eigen::Vector3f::Zero()) : d);
    }
  }
  per_pixel.angles = directions;
  ScanImage image;
  image.name = "camera";
  image.format = "png";
  image.width = 2;
  image.height = 1;
  image.data = {0x89, 'P', 'N', 'G', 1, 2, 3};
  std::vector<E57ScanOutput> outputs(2);
  outputs[0].scan = &spherical;
  outputs[0].guid = "{kept-guid}";
  outputs[0].images = {image};
  outputs[1].scan = &per_pixel;
  const auto path = dir.path() / "out.e57";
  write_e57(path, outputs, {});
  const std::vector<ImportedScan> scans = read_all(path);
  ASSERT_EQ(scans.size(), 2u);
  expect_same_scan(spherical, scans[0].scan);
  expect_same_scan(per_pixel, scans[1].scan);
  EXPECT_EQ(scans[0].scan.T_world_scan.translation(), georeferenced.translation());
  EXPECT_EQ(scans[0].scan.name, "hall ]]> & <north> é");
  EXPECT_EQ(scans[0].scan.scanner.name, "virtual");
  EXPECT_EQ(scans[0].source.guid, "{kept-guid}");
  EXPECT_THAT(scans[1].source.guid, ::testing::StartsWith("{"));
  EXPECT_EQ(scans[0].source.unplaced_points, 0u);
  ASSERT_EQ(scans[0].images.size(), 1u);
  EXPECT_EQ(scans[0].images[0].data, image.data);
  EXPECT_EQ(scans[0].images[0].name, "camera");
  EXPECT_TRUE(scans[1].images.empty());
}

TEST(WriteE57, AKeepMaskLeavesOnlyTheKeptPixelsValid) {
  const ScratchDir dir;
  const Scan scan = panorama(Eigen::Isometry3d::Identity());
  std::vector<std::uint8_t> keep(scan.pixel_count(), 0);
  for (std::size_t i = 0; i < keep.size(); i += 3) keep[i] = 1;
  std::vector<E57ScanOutput> outputs(1);
  outputs[0].scan = &scan;
  outputs[0].keep = &keep;
  const auto path = dir.path() / "merged.e57";
  write_e57(path, outputs, {});
  const Scan read = read_all(path).at(0).scan;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    EXPECT_EQ(read.valid[i] != 0, scan.valid[i] && keep[i]) << i;
  }
}

TEST(WriteE57, AFailedWriteLeavesNoFile) {
  const ScratchDir dir;
  Scan scan = panorama(Eigen::Isometry3d::Identity());
  scan.range_m[1] = 5e5f;  // beyond what the range field holds
  std::vector<E57ScanOutput> outputs(1);
  outputs[0].scan = &scan;
  const auto path = dir.path() / "far.e57";
  EXPECT_THROW(write_e57(path, outputs, {}), core::InputError);
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace scanbench::acquisition
