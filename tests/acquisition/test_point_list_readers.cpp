// PLY and LAS import: files assembled byte by byte here (an independent
// writer: every header field and record as the specifications lay them
// out), our own exports read back whole, and every class of bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "acquisition/formats/las_reader.hpp"
#include "acquisition/formats/ply_reader.hpp"
#include "acquisition/formats/point_export.hpp"
#include "acquisition/formats/scan_files.hpp"
#include "acquisition/local_origin.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::ScratchDir;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

template <typename T>
void put(std::string& out, T value, bool big_endian = false) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

Eigen::Vector3d point_k(const Scan& scan, std::size_t k) {
  return point_in_world(scan, static_cast<int>(k) / scan.columns,
                        static_cast<int>(k) % scan.columns);
}

// A closed sphere seen from the origin (half of it behind the other half),
// 3 000 points in a shuffled order, with colours.
Scan sphere_scan() {
  std::vector<Eigen::Vector3d> points;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < 3000; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / 3000.0, r = std::sqrt(1.0 - z * z);
    points.emplace_back(6.0 + r * std::cos(golden * k), -2.0 + r * std::sin(golden * k), z);
  }
  std::shuffle(points.begin(), points.end(), std::mt19937(3));
  Scan scan = make_scattered_scan(points.size(), true, true);
  for (std::size_t k = 0; k < points.size(); ++k) {
    scan.intensity[k] = static_cast<float>(k % 101) / 100.0f;
    for (int c = 0; c < 3; ++c)
      scan.rgb[3 * k + c] = static_cast<std::uint8_t>((k * (c + 3)) % 256);
  }
  set_scattered_points(scan, points);
  return scan;
}

void expect_same_cloud(const Scan& read, const Scan& written, bool intensity_in_u16) {
  ASSERT_TRUE(read.is_scattered());
  ASSERT_EQ(count_valid(read), count_valid(written));
  double worst = 0.0;
  for (std::size_t k = 0; k < count_valid(written); ++k) {
    worst = std::max(worst, (point_k(read, k) - point_k(written, k)).norm());
    EXPECT_NEAR(read.intensity[k], written.intensity[k], intensity_in_u16 ? 1e-5 : 0.0);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(read.rgb[3 * k + c], written.rgb[3 * k + c]) << k;
  }
  EXPECT_LT(worst, 1e-4) << "every point within 0.1 mm, in the same order";
}

TEST(PlyReader, OurBinaryExportComesBackWholeInItsOrder) {
  const ScratchDir dir;
  const Scan sphere = sphere_scan();
  write_ply(dir / "sphere.ply", std::span(&sphere, 1));
  const ImportedScan read = read_ply(dir / "sphere.ply");
  EXPECT_EQ(read.source.format, "ply");
  EXPECT_EQ(read.source.points_in_file, 3000u);
  EXPECT_EQ(read.scan.name, "sphere");
  expect_same_cloud(read.scan, sphere, false);
}

TEST(PlyReader, AsciiWithAFaceElementAndCloudCompareNames) {
  const ScratchDir dir;
  write_bytes(dir / "a.ply",
              "ply\nformat ascii 1.0\ncomment by hand\nelement vertex 3\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property uchar red\nproperty uchar green\nproperty uchar blue\n"
              "property float scalar_Intensity\nelement face 1\n"
              "property list uchar int vertex_indices\nend_header\n"
              "1 0 0 255 0 0 0.5\n0 1.5 0 0 255 0 0.25\n0 0 2 0 0 255 1\n3 0 1 2\n");
  const ImportedScan read = read_ply(dir / "a.ply");
  ASSERT_EQ(count_valid(read.scan), 3u);
  EXPECT_LT((point_k(read.scan, 1) - Eigen::Vector3d(0, 1.5, 0)).norm(), 1e-6);
  EXPECT_FLOAT_EQ(read.scan.intensity[2], 1.0f);
  EXPECT_EQ(read.scan.rgb[4], 255);
}

TEST(PlyReader, APointAtTheFilesOriginKeepsItsPlace) {
  // Measured from the file's origin, that point would have no direction:
  // the scan's origin moves to the centroid instead.
  const ScratchDir dir;
  write_bytes(dir / "o.ply",
              "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
              "property double z\nend_header\n0 0 0\n2.5 -1 0.25\n-3 4 1\n");
  const ImportedScan read = read_ply(dir / "o.ply");
  ASSERT_EQ(count_valid(read.scan), 3u);
  const Eigen::Vector3d expected[3] = {{0, 0, 0}, {2.5, -1, 0.25}, {-3, 4, 1}};
  for (std::size_t k = 0; k < 3; ++k) {
    ASSERT_TRUE(point_k(read.scan, k).allFinite()) << k;
    EXPECT_LT((point_k(read.scan, k) - expected[k]).norm(), 1e-6) << k;
  }
}

TEST(PlyReader, BigEndianWithAListBeforeTheVerticesAndSixteenBitColour) {
  const ScratchDir dir;
  std::string ply =
      "ply\nformat binary_big_endian 1.0\nelement camera 1\n"
      "property list uchar float params\nelement vertex 2\n"
      "property double x\nproperty double y\nproperty double z\nproperty ushort red\n"
      "property ushort green\nproperty ushort blue\nproperty int8 flag\nend_header\n";
  put<std::uint8_t>(ply, 2);
  put<float>(ply, 1.0f, true);
  put<float>(ply, 2.0f, true);
  for (const double v : {10.25, -3.5, 1.125}) put<double>(ply, v, true);
  for (const std::uint16_t v : {65535, 0, 32896}) put<std::uint16_t>(ply, v, true);
  put<std::int8_t>(ply, -1);
  for (const double v : {NAN, NAN, NAN}) put<double>(ply, v, true);  // no return
  for (int c = 0; c < 3; ++c) put<std::uint16_t>(ply, 0, true);
  put<std::int8_t>(ply, 0);
  write_bytes(dir / "b.ply", ply);
  const ImportedScan read = read_ply(dir / "b.ply");
  EXPECT_EQ(read.source.points_in_file, 2u);
  ASSERT_EQ(count_valid(read.scan), 1u);
  EXPECT_LT((point_k(read.scan, 0) - Eigen::Vector3d(10.25, -3.5, 1.125)).norm(), 1e-5);
  EXPECT_EQ(read.scan.rgb[0], 255);
  EXPECT_EQ(read.scan.rgb[1], 0);
  EXPECT_EQ(read.scan.rgb[2], 128);
}

TEST(PlyReader, BadFilesAreRefusedWithTheirPlace) {
  const ScratchDir dir;
  const auto refused = [&](const std::string& bytes, const std::string& problem) {
    write_bytes(dir / "bad.ply", bytes);
    EXPECT_THAT([&] { read_ply(dir / "bad.ply"); },
                ThrowsMessage<core::InputError>(HasSubstr(problem)))
        << bytes;
  };
  refused("plx\n", "not a PLY file");
  refused(
      "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n",
      "holds no points");
  refused("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
          "no x, y and z");
  refused(
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n0123456789ab",
      "truncated body: vertex 0 is missing");
  refused(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n",
      "truncated body: vertex 1 of 2 is missing");
  refused("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
          "unknown property type \"quad\"");
  refused("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "no end_header line");
  // Found by fuzzing: a count no file could hold, and values no survey has.
  refused(
      "ply\nformat binary_little_endian 1.0\nelement camera 18446744073709551615\n"
      "property uchar k\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n",
      "claims 18446744073709551615 records");
  refused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "end_header\n1 2 3e9 -7 1e12 300\n",
      "vertex 0: coordinate beyond 10^8 m");
}

// A LAS 1.2 file of point data format 3, laid out as the specification
// says, with a GeoTIFF key directory naming EPSG:25832 and 16-bit colour.
std::string las_1_2(std::uint32_t points_in_header) {
  const std::uint16_t header_size = 227, record = 34;
  std::string vlr;
  put<std::uint16_t>(vlr, 0);
  vlr += std::string("LASF_Projection").append(1, '\0');
  put<std::uint16_t>(vlr, 34735);
  const std::uint16_t keys[] = {1, 1, 0, 2, 1024, 0, 1, 1, 3072, 0, 1, 25832};
  put<std::uint16_t>(vlr, sizeof keys);
  vlr += std::string(32, '\0');
  for (const std::uint16_t k : keys) put<std::uint16_t>(vlr, k);
  std::string h = "LASF";
  h += std::string(20, '\0');
  h += '\x01';
  h += '\x02';
  h += std::string(68, '\0');
  put<std::uint16_t>(h, header_size);
  put<std::uint32_t>(h, static_cast<std::uint32_t>(header_size + vlr.size()));
  put<std::uint32_t>(h, 1);
  h += '\x03';
  put<std::uint16_t>(h, record);
  put<std::uint32_t>(h, points_in_header);
  h += std::string(20, '\0');
  for (int axis = 0; axis < 3; ++axis) put<double>(h, 0.001);
  for (const double offset : {512000.0, 5400000.0, 300.0}) put<double>(h, offset);
  h += std::string(48, '\0');
  std::string body;
  for (int k = 0; k < 2; ++k) {
    for (const std::int32_t v : {1234 + k, -5678, 250}) put<std::int32_t>(body, v);
    put<std::uint16_t>(body, k == 0 ? 65535 : 0);
    body += std::string(6, '\0');  // return bits, class, angle, user data, source id
    put<double>(body, 0.0);        // GPS time
    for (const std::uint16_t c : {65535, 32896, 0}) put<std::uint16_t>(body, c);
  }
  return h + vlr + body;
}

TEST(LasReader, AVersionOneTwoFileKeepsItsPointsChannelsAndCoordinateSystem) {
  const ScratchDir dir;
  write_bytes(dir / "a.las", las_1_2(2));
  const ImportedScan read = read_las(dir / "a.las");
  EXPECT_EQ(read.source.format, "las");
  EXPECT_EQ(read.source.coordinate_metadata, "EPSG:25832");
  ASSERT_EQ(count_valid(read.scan), 2u);
  EXPECT_LT((point_k(read.scan, 1) - Eigen::Vector3d(512001.235, 5399994.322, 300.25)).norm(),
            1e-4);
  EXPECT_FLOAT_EQ(read.scan.intensity[0], 1.0f);
  EXPECT_EQ(read.scan.rgb[0], 255);
  EXPECT_EQ(read.scan.rgb[1], 128);
  EXPECT_EQ(read.scan.rgb[2], 0);
}

TEST(LasReader, OurVersionOneFourExportComesBackWholeInItsOrder) {
  const ScratchDir dir;
  const Scan sphere = sphere_scan();
  const std::uint16_t source = 1;
  write_las(dir / "sphere.las", std::span(&sphere, 1), std::span(&source, 1));
  const ImportedScan read = read_las(dir / "sphere.las");
  EXPECT_EQ(read.source.points_in_file, 3000u);
  expect_same_cloud(read.scan, sphere, true);
}

TEST(LasReader, OurExportNamesItsCoordinateSystemInWkt) {
  const ScratchDir dir;
  const Scan sphere = sphere_scan();
  const std::uint16_t source = 1;
  const std::string wkt =
      "PROJCS[\"ETRS89 / UTM zone 32N\",GEOGCS[\"ETRS89\",DATUM[\"European_Terrestrial_"
      "Reference_System_1989\",SPHEROID[\"GRS 1980\",6378137,298.257222101]],PRIMEM["
      "\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Transverse_"
      "Mercator\"],PARAMETER[\"central_meridian\",9],PARAMETER[\"scale_factor\",0.9996],"
      "PARAMETER[\"false_easting\",500000],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"25832\"]]";
  EXPECT_TRUE(looks_like_wkt(wkt));
  EXPECT_TRUE(looks_like_wkt("  COMPOUNDCRS[\"a\",x]\n"));
  EXPECT_FALSE(looks_like_wkt("EPSG:25832"));
  EXPECT_FALSE(looks_like_wkt("[]"));
  write_las(dir / "sphere.las", std::span(&sphere, 1), std::span(&source, 1), {}, {}, wkt);
  const ImportedScan read = read_las(dir / "sphere.las");
  EXPECT_EQ(read.source.coordinate_metadata, wkt);
  expect_same_cloud(read.scan, sphere, true);
}

TEST(LasReader, BadFilesAreRefusedWithTheirPlace) {
  const ScratchDir dir;
  std::string laz = las_1_2(2);
  laz[104] = static_cast<char>(0x83);
  write_bytes(dir / "a.las", laz);
  EXPECT_THAT([&] { read_las(dir / "a.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("LAZ (LASzip-compressed)")));
  write_bytes(dir / "b.las", las_1_2(3));
  EXPECT_THAT([&] { read_las(dir / "b.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("records are cut short")));
  write_bytes(dir / "c.las", "LASX" + las_1_2(2).substr(4));
  EXPECT_THAT([&] { read_las(dir / "c.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("not a LAS file")));
  write_bytes(dir / "d.las", las_1_2(2).substr(0, 100));
  EXPECT_THAT([&] { read_las(dir / "d.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("the header is cut short")));
  std::string far = las_1_2(2);
  for (int k = 0; k < 3; ++k) {  // a scale of 10^12
    const double scale = 1e12;
    std::memcpy(far.data() + 131 + 8 * k, &scale, 8);
  }
  write_bytes(dir / "f.las", far);
  EXPECT_THAT([&] { read_las(dir / "f.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("record 0: coordinate beyond 10^8 m")));
  std::string small_header = las_1_2(2);
  small_header[94] = static_cast<char>(200);  // header size 200 < 227
  write_bytes(dir / "g.las", small_header);
  EXPECT_THAT([&] { read_las(dir / "g.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("a header size of 200 bytes, less than")));
  std::string inside = las_1_2(2);
  inside[96] = static_cast<char>(100);  // points at byte 100, inside the header
  inside[97] = 0;
  write_bytes(dir / "h.las", inside);
  EXPECT_THAT([&] { read_las(dir / "h.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("inside the 227-byte header")));
  write_bytes(dir / "i.las", las_1_2(0).substr(0, las_1_2(0).size() - 2 * 34));
  EXPECT_THAT([&] { read_las(dir / "i.las"); },
              ThrowsMessage<core::InputError>(HasSubstr("holds no points")));
  write_bytes(dir / "e.laz", "");
  EXPECT_THAT([&] { scan_file_format(dir / "e.laz"); },
              ThrowsMessage<core::InputError>(HasSubstr("Debian does not package LASzip")));
}

}  // namespace
}  // namespace scanbench::acquisition
