// PLY and LAS import: files assembled byte by byte here (an independent
// writer: every header field and record as the specifications lay them
// out), our own exports read back whole, and every class of bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <optional>
#include <random>
#include <string>

#include "acquisition/formats/las_reader.hpp"
#include "acquisition/formats/ply_reader.hpp"
#include "acquisition/formats/point_export.hpp"
#include "acquisition/formats/scan_files.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/local_origin.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::ScratchDir;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// The one scan a reader makes of a cloud narrow enough for one.
ImportedScan only(std::vector<ImportedScan> scans) {
  EXPECT_EQ(scans.size(), 1u);
  return std::move(scans.at(0));
}

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
  const ImportedScan read = only(read_ply(dir / "sphere.ply"));
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
  const ImportedScan read = only(read_ply(dir / "a.ply"));
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
  const ImportedScan read = only(read_ply(dir / "o.ply"));
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
  const ImportedScan read = only(read_ply(dir / "b.ply"));
  EXPECT_EQ(read.source.points_in_file, 2u);
  ASSERT_EQ(count_valid(read.scan), 1u);
  EXPECT_LT((point_k(read.scan, 0) - Eigen::Vector3d(10.25, -3.5, 1.125)).norm(), 1e-5);
  EXPECT_EQ(read.scan.rgb[0], 255);
  EXPECT_EQ(read.scan.rgb[1], 0);
  EXPECT_EQ(read.scan.rgb[2], 128);
}

// The normals and footprints `read` recorded are those `geometry` of
// `written` exported: in the world frame, within float rounding.
void expect_recorded_geometry(const ImportedScan& read, const Scan& written,
                              const ScanGeometry& geometry) {
  const std::size_t n = count_valid(written);
  ASSERT_EQ(read.recorded.normal.size(), read.scan.pixel_count());
  ASSERT_EQ(read.recorded.footprint_m.size(), read.scan.pixel_count());
  const Eigen::Matrix3f to_world_read = read.scan.T_world_scan.linear().cast<float>();
  const Eigen::Matrix3f to_world_written = written.T_world_scan.linear().cast<float>();
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3f expected = to_world_written * geometry.normal[k];
    EXPECT_LT((to_world_read * read.recorded.normal[k] - expected).norm(), 1e-6f) << k;
    EXPECT_EQ(read.recorded.footprint_m[k], geometry.footprint_m[k]) << k;
  }
}

// The geometry of `read` keeps what its file recorded, even a normal facing
// away from the viewpoint, and fits one where the file has none, on the
// side of the recorded ones around it.
void expect_recorded_geometry_kept(ImportedScan read) {
  const std::size_t n = count_valid(read.scan);
  read.recorded.normal[0] = -read.recorded.normal[0];
  const Eigen::Vector3f exported = read.recorded.normal[1];
  read.recorded.normal[1].setZero();
  read.recorded.footprint_m[2] = 0.0f;
  const GeometryResult result = compute_geometry(read.scan, {}, read.recorded);
  EXPECT_EQ(result.normals, n);
  EXPECT_EQ(result.recorded_normals, n - 1);
  const ScanGeometry& g = result.geometry;
  for (std::size_t k = 0; k < n; ++k) {
    if (k == 1) continue;
    EXPECT_EQ(g.normal[k], read.recorded.normal[k]) << k;
    EXPECT_GT(g.confidence[k], 0.0f) << k;
    EXPECT_EQ(g.flags[k] & kFlagNoNormal, 0) << k;
    if (k != 2) {
      EXPECT_EQ(g.footprint_m[k], read.recorded.footprint_m[k]) << k;
    }
  }
  EXPECT_TRUE(g.has_normal(1));  // fitted to its neighbours instead
  EXPECT_GT(g.normal[1].dot(exported), 0.99f) << "the side of its neighbours'";
  EXPECT_GT(g.footprint_m[2], 0.0f);
  // Every recorded normal facing away from the viewpoint (outward on the
  // sphere, as a mesh has them): the fitted one faces away too.
  for (Eigen::Vector3f& normal : read.recorded.normal) normal = -normal;
  const ScanGeometry outward = compute_geometry(read.scan, {}, read.recorded).geometry;
  EXPECT_GT(outward.normal[1].dot(-exported), 0.99f);
}

TEST(PlyReader, OurExportsNormalsAndFootprintsAreKept) {
  const ScratchDir dir;
  const Scan sphere = sphere_scan();
  const ScanGeometry geometry = compute_geometry(sphere).geometry;
  const std::vector<const ScanGeometry*> geometry_of = {&geometry};
  write_ply(dir / "sphere.ply", std::span(&sphere, 1), geometry_of);
  const ImportedScan read = only(read_ply(dir / "sphere.ply"));
  expect_same_cloud(read.scan, sphere, false);
  expect_recorded_geometry(read, sphere, geometry);
  expect_recorded_geometry_kept(read);
}

TEST(PlyReader, NormalsOfAnyLengthAndFootprintsOfCloudCompareNames) {
  const ScratchDir dir;
  write_bytes(dir / "n.ply",
              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nproperty float Nx\nproperty float Ny\nproperty float Nz\n"
              "property float footprint\nend_header\n"
              "1 0 0 0 0 2 0.01\n0 1 0 0 0 0 0\n0 0 1 3 -4 0 -1\n");
  const ImportedScan read = only(read_ply(dir / "n.ply"));
  ASSERT_EQ(read.recorded.normal.size(), read.scan.pixel_count());
  const Eigen::Matrix3f to_world = read.scan.T_world_scan.linear().cast<float>();
  EXPECT_LT((to_world * read.recorded.normal[0] - Eigen::Vector3f(0, 0, 1)).norm(), 1e-6f);
  EXPECT_TRUE(read.recorded.normal[1].isZero()) << "0 0 0 is no normal";
  EXPECT_LT((to_world * read.recorded.normal[2] - Eigen::Vector3f(0.6f, -0.8f, 0)).norm(), 1e-6f);
  EXPECT_FLOAT_EQ(read.recorded.footprint_m[0], 0.01f);
  EXPECT_EQ(read.recorded.footprint_m[1], 0.0f) << "0 is no footprint";
  EXPECT_EQ(read.recorded.footprint_m[2], 0.0f) << "nor is a negative one";
  write_bytes(dir / "plain.ply",
              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n1 2 3\n");
  EXPECT_TRUE(only(read_ply(dir / "plain.ply")).recorded.empty());
}

TEST(PlyReader, ACloudTooWideForOneScanIsTiledKeepingEveryPointAndItsNormal) {
  // Two groups 5 km apart, interleaved in the file: float ranges from one
  // centre would put the far ones 0.15 mm off; one scan per 400 m cube
  // keeps them, each group in the file's order.
  const ScratchDir dir;
  write_bytes(dir / "c.ply",
              "ply\nformat ascii 1.0\nelement vertex 6\nproperty double x\nproperty double y\n"
              "property double z\nproperty float nx\nproperty float ny\nproperty float nz\n"
              "end_header\n"
              "1.0001 2 3 1 0 0\n5000.0003 2 3 0 1 0\n1 2.5 3.0002 1 0 0\n"
              "5001.25 2.0001 3 0 1 0\n1 3 3 1 0 0\n5000 2 3.75 0 1 0\n");
  const std::vector<ImportedScan> scans = read_ply(dir / "c.ply");
  ASSERT_EQ(scans.size(), 2u);
  const Eigen::Vector3d near[3] = {{1.0001, 2, 3}, {1, 2.5, 3.0002}, {1, 3, 3}};
  const Eigen::Vector3d far[3] = {{5000.0003, 2, 3}, {5001.25, 2.0001, 3}, {5000, 2, 3.75}};
  for (std::size_t s = 0; s < 2; ++s) {
    const ImportedScan& tile = scans[s];
    EXPECT_EQ(tile.scan.name, "c-" + std::to_string(s + 1));
    EXPECT_EQ(tile.source.points_in_file, 3u);
    EXPECT_LE(tile.scan.import_round_trip_m, kPromisedRoundTripM);
    ASSERT_EQ(count_valid(tile.scan), 3u);
    const Eigen::Matrix3f to_world = tile.scan.T_world_scan.linear().cast<float>();
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_LT((point_k(tile.scan, k) - (s == 0 ? near : far)[k]).norm(), 1e-4) << s << k;
      EXPECT_LT((to_world * tile.recorded.normal[k] -
                 (s == 0 ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY()))
                    .norm(),
                1e-6f);
    }
  }
}

TEST(PlyReader, BadFilesAreRefusedWithTheirPlace) {
  const ScratchDir dir;
  const auto refused = [&](const std::string& bytes, const std::string& problem) {
    write_bytes(dir / "bad.ply", bytes);
    EXPECT_THAT([&] { only(read_ply(dir / "bad.ply")); },
                ThrowsMessage<core::InputError>(HasSubstr(problem)))
        << bytes;
  };
  refused("plx\n", "not a PLY file");
  refused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty list uchar uchar red\nproperty uchar green\n"
      "property uchar blue\nend_header\n1 2 3 1 9 4 5\n",
      "the vertex property \"red\" is a list");
  refused(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float nz\nend_header\n1 2 3 0 1\n",
      "some but not all of nx, ny and nz");
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

// One extra bytes descriptor (LAS 1.4 R15 table 24): `type`, and a
// no-data value, scale and offset where given.
std::string extra_descriptor(const std::string& name, std::uint8_t type,
                             std::optional<std::int64_t> no_data = std::nullopt,
                             std::optional<double> scale = std::nullopt,
                             std::optional<double> offset = std::nullopt) {
  std::string d(192, '\0');
  d[2] = static_cast<char>(type);
  d[3] = static_cast<char>((no_data ? 0x01 : 0) | (scale ? 0x08 : 0) | (offset ? 0x10 : 0));
  std::copy(name.begin(), name.end(), d.begin() + 4);
  if (no_data) std::memcpy(d.data() + 40, &*no_data, 8);  // an anytype: widened to 64 bits
  if (scale) std::memcpy(d.data() + 112, &*scale, 8);
  if (offset) std::memcpy(d.data() + 136, &*offset, 8);
  return d;
}

// A LAS 1.2 file of point data format 3, laid out as the specification
// says, with a GeoTIFF key directory naming EPSG:25832 and 16-bit colour;
// with `descriptors`, an extra bytes record and `extra[k]` after record k.
std::string las_1_2(std::uint32_t points_in_header, const std::string& descriptors = {},
                    const std::vector<std::string>& extra = {}) {
  const std::uint16_t header_size = 227;
  const auto record = static_cast<std::uint16_t>(34 + (extra.empty() ? 0 : extra[0].size()));
  std::string vlr;
  put<std::uint16_t>(vlr, 0);
  vlr += std::string("LASF_Projection").append(1, '\0');
  put<std::uint16_t>(vlr, 34735);
  const std::uint16_t keys[] = {1, 1, 0, 2, 1024, 0, 1, 1, 3072, 0, 1, 25832};
  put<std::uint16_t>(vlr, sizeof keys);
  vlr += std::string(32, '\0');
  for (const std::uint16_t k : keys) put<std::uint16_t>(vlr, k);
  if (!descriptors.empty()) {
    put<std::uint16_t>(vlr, 0);
    vlr += std::string("LASF_Spec").append(7, '\0');
    put<std::uint16_t>(vlr, 4);
    put<std::uint16_t>(vlr, static_cast<std::uint16_t>(descriptors.size()));
    vlr += std::string(32, '\0');
    vlr += descriptors;
  }
  std::string h = "LASF";
  h += std::string(20, '\0');
  h += '\x01';
  h += '\x02';
  h += std::string(68, '\0');
  put<std::uint16_t>(h, header_size);
  put<std::uint32_t>(h, static_cast<std::uint32_t>(header_size + vlr.size()));
  put<std::uint32_t>(h, descriptors.empty() ? 1 : 2);
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
    if (!extra.empty()) body += extra[static_cast<std::size_t>(k)];
  }
  return h + vlr + body;
}

TEST(LasReader, AVersionOneTwoFileKeepsItsPointsChannelsAndCoordinateSystem) {
  const ScratchDir dir;
  write_bytes(dir / "a.las", las_1_2(2));
  const ImportedScan read = only(read_las(dir / "a.las"));
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
  const ImportedScan read = only(read_las(dir / "sphere.las"));
  EXPECT_EQ(read.source.points_in_file, 3000u);
  expect_same_cloud(read.scan, sphere, true);
}

TEST(LasReader, OurExportsNormalsAndFootprintsAreKept) {
  const ScratchDir dir;
  const Scan sphere = sphere_scan();
  const ScanGeometry geometry = compute_geometry(sphere).geometry;
  const std::vector<const ScanGeometry*> geometry_of = {&geometry};
  const std::uint16_t source = 1;
  write_las(dir / "sphere.las", std::span(&sphere, 1), std::span(&source, 1), geometry_of);
  const ImportedScan read = only(read_las(dir / "sphere.las"));
  expect_same_cloud(read.scan, sphere, true);
  expect_recorded_geometry(read, sphere, geometry);
  expect_recorded_geometry_kept(read);
}

TEST(LasReader, ExtraBytesScaledWithNoDataAndOtherFieldsAround) {
  // A byte of another field, then normals as scaled 16-bit integers with a
  // no-data value, and a footprint in millimetres with an offset.
  const std::string descriptors = extra_descriptor("classification_confidence", 1) +
                                  extra_descriptor("normal_x", 4, -32768, 1.0 / 32767) +
                                  extra_descriptor("normal_y", 4, -32768, 1.0 / 32767) +
                                  extra_descriptor("Normal Z", 4, -32768, 1.0 / 32767) +
                                  extra_descriptor("Footprint", 3, std::nullopt, 0.001, 0.0005);
  std::vector<std::string> extra(2);
  put<std::uint8_t>(extra[0], 7);
  for (const std::int16_t v : {0, 0, 32767}) put<std::int16_t>(extra[0], v);
  put<std::uint16_t>(extra[0], 12);
  put<std::uint8_t>(extra[1], 7);
  for (const std::int16_t v : {-32768, 0, 0}) put<std::int16_t>(extra[1], v);  // no data
  put<std::uint16_t>(extra[1], 0);
  const ScratchDir dir;
  write_bytes(dir / "x.las", las_1_2(2, descriptors, extra));
  const ImportedScan read = only(read_las(dir / "x.las"));
  EXPECT_EQ(read.source.coordinate_metadata, "EPSG:25832");
  ASSERT_EQ(count_valid(read.scan), 2u);
  EXPECT_LT((point_k(read.scan, 1) - Eigen::Vector3d(512001.235, 5399994.322, 300.25)).norm(),
            1e-4);
  ASSERT_EQ(read.recorded.normal.size(), read.scan.pixel_count());
  const Eigen::Matrix3f to_world = read.scan.T_world_scan.linear().cast<float>();
  EXPECT_LT((to_world * read.recorded.normal[0] - Eigen::Vector3f(0, 0, 1)).norm(), 1e-6f);
  EXPECT_TRUE(read.recorded.normal[1].isZero()) << "a no-data component: no normal";
  EXPECT_FLOAT_EQ(read.recorded.footprint_m[0], 0.0125f);
  EXPECT_FLOAT_EQ(read.recorded.footprint_m[1], 0.0005f);

  // A value beyond a float is none.
  std::vector<std::string> huge(2);
  for (std::string& record : huge) put<double>(record, 1e300);
  write_bytes(dir / "h.las", las_1_2(2, extra_descriptor("Footprint", 10), huge));
  const ImportedScan beyond = only(read_las(dir / "h.las"));
  EXPECT_EQ(beyond.recorded.footprint_m[0], 0.0f);

  // Damaged records: a part of a normal, a field beyond the record, a
  // field of no bytes or of an unknown type, a record of part of a
  // descriptor.
  write_bytes(dir / "y.las",
              las_1_2(2, extra_descriptor("NormalX", 9) + extra_descriptor("NormalY", 9),
                      {std::string(8, '\0'), std::string(8, '\0')}));
  EXPECT_THAT([&] { only(read_las(dir / "y.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("some but not all of NormalX")));
  write_bytes(dir / "v.las", las_1_2(2, extra_descriptor("empty", 0), {"", ""}));
  EXPECT_THAT([&] { only(read_las(dir / "v.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("field \"empty\" has no bytes")));
  write_bytes(dir / "u.las",
              las_1_2(2, extra_descriptor("Footprint", 9).substr(0, 100), {"1234", "5678"}));
  EXPECT_THAT([&] { only(read_las(dir / "u.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("not a whole number of 192-byte")));
  write_bytes(dir / "z.las", las_1_2(2, extra_descriptor("Footprint", 10), {"1234", "5678"}));
  EXPECT_THAT([&] { only(read_las(dir / "z.las")); },
              ThrowsMessage<core::InputError>(
                  HasSubstr("extra bytes field \"Footprint\" ends at byte 42 of 38-byte records")));
  write_bytes(dir / "w.las", las_1_2(2, extra_descriptor("odd", 31), {"1234", "5678"}));
  EXPECT_THAT([&] { only(read_las(dir / "w.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("unknown data type 31")));
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
  const ImportedScan read = only(read_las(dir / "sphere.las"));
  EXPECT_EQ(read.source.coordinate_metadata, wkt);
  expect_same_cloud(read.scan, sphere, true);
}

TEST(LasReader, BadFilesAreRefusedWithTheirPlace) {
  const ScratchDir dir;
  std::string laz = las_1_2(2);
  laz[104] = static_cast<char>(0x83);
  write_bytes(dir / "a.las", laz);
  EXPECT_THAT([&] { only(read_las(dir / "a.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("LAZ (LASzip-compressed)")));
  write_bytes(dir / "b.las", las_1_2(3));
  EXPECT_THAT([&] { only(read_las(dir / "b.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("records are cut short")));
  write_bytes(dir / "c.las", "LASX" + las_1_2(2).substr(4));
  EXPECT_THAT([&] { only(read_las(dir / "c.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("not a LAS file")));
  write_bytes(dir / "d.las", las_1_2(2).substr(0, 100));
  EXPECT_THAT([&] { only(read_las(dir / "d.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("the header is cut short")));
  std::string far = las_1_2(2);
  for (int k = 0; k < 3; ++k) {  // a scale of 10^12
    const double scale = 1e12;
    std::memcpy(far.data() + 131 + 8 * k, &scale, 8);
  }
  write_bytes(dir / "f.las", far);
  EXPECT_THAT([&] { only(read_las(dir / "f.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("record 0: coordinate beyond 10^8 m")));
  std::string small_header = las_1_2(2);
  small_header[94] = static_cast<char>(200);  // header size 200 < 227
  write_bytes(dir / "g.las", small_header);
  EXPECT_THAT([&] { only(read_las(dir / "g.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("a header size of 200 bytes, less than")));
  std::string inside = las_1_2(2);
  inside[96] = static_cast<char>(100);  // points at byte 100, inside the header
  inside[97] = 0;
  write_bytes(dir / "h.las", inside);
  EXPECT_THAT([&] { only(read_las(dir / "h.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("inside the 227-byte header")));
  write_bytes(dir / "i.las", las_1_2(0).substr(0, las_1_2(0).size() - 2 * 34));
  EXPECT_THAT([&] { only(read_las(dir / "i.las")); },
              ThrowsMessage<core::InputError>(HasSubstr("holds no points")));
  write_bytes(dir / "e.laz", "");
  EXPECT_THAT([&] { scan_file_format(dir / "e.laz"); },
              ThrowsMessage<core::InputError>(HasSubstr("Debian does not package LASzip")));
}

}  // namespace
}  // namespace scanbench::acquisition
