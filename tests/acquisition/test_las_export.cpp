// LAS 1.4 export read back by a minimal reader of its own, written from the
// specification's tables (LAS 1.4 R15): the header's fields, the extra
// bytes VLR, and every point's coordinates (within 0.05 mm of the world
// point, on a georeferenced site), intensity, colour, source id and
// geometry.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>

#include "acquisition/formats/point_export.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::ScratchDir;

// A wall 10 m ahead seen by a 40 × 60 grid, at a georeferenced pose.
Scan wall_scan(const Eigen::Vector3d& position) {
  constexpr int kRows = 40, kColumns = 60;
  constexpr double kStep = 0.2 * 3.14159265358979323846 / 180.0;
  Scan scan = make_empty_scan(kRows, kColumns, true, true);
  scan.angles = SphericalAngles{0.5 * kColumns * kStep, -kStep, 0.5 * kRows * kStep, -kStep};
  scan.T_world_scan =
      Eigen::Translation3d(position) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kColumns; ++col) {
      const std::size_t i = scan.index(row, col);
      if ((row * 7 + col) % 11 == 0) continue;  // some invalid pixels
      const Eigen::Vector3d d = direction_precise(scan, row, col);
      scan.valid[i] = 1;
      scan.range_m[i] = static_cast<float>(10.0 / d.x());
      scan.intensity[i] = static_cast<float>((row + col) % 10) / 9.0f;
      scan.rgb[3 * i] = static_cast<std::uint8_t>(row * 6);
      scan.rgb[3 * i + 1] = static_cast<std::uint8_t>(col * 4);
      scan.rgb[3 * i + 2] = 255;
    }
  }
  return scan;
}

template <typename T>
T at(const std::string& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

struct LasPoint {
  Eigen::Vector3d position;
  std::uint16_t intensity = 0;
  std::uint8_t returns = 0;
  std::uint16_t source = 0;
  std::array<std::uint16_t, 3> rgb{};
  std::array<float, 4> extra{};
};

struct LasFile {
  std::string bytes;
  std::uint32_t point_offset = 0;
  std::uint16_t record_length = 0;
  std::uint64_t points = 0;
  Eigen::Vector3d scale, offset, min, max;

  explicit LasFile(const std::filesystem::path& file) : bytes(test::read_file_bytes(file)) {
    point_offset = at<std::uint32_t>(bytes, 96);
    record_length = at<std::uint16_t>(bytes, 105);
    points = at<std::uint64_t>(bytes, 247);
    for (int a = 0; a < 3; ++a) {
      scale[a] = at<double>(bytes, 131 + 8 * static_cast<std::size_t>(a));
      offset[a] = at<double>(bytes, 155 + 8 * static_cast<std::size_t>(a));
      max[a] = at<double>(bytes, 179 + 16 * static_cast<std::size_t>(a));
      min[a] = at<double>(bytes, 187 + 16 * static_cast<std::size_t>(a));
    }
  }

  LasPoint point(std::size_t k) const {
    const std::size_t p = point_offset + k * record_length;
    LasPoint out;
    for (int a = 0; a < 3; ++a)
      out.position[a] =
          at<std::int32_t>(bytes, p + 4 * static_cast<std::size_t>(a)) * scale[a] + offset[a];
    out.intensity = at<std::uint16_t>(bytes, p + 12);
    out.returns = static_cast<std::uint8_t>(bytes[p + 14]);
    out.source = at<std::uint16_t>(bytes, p + 20);
    for (std::size_t c = 0; c < 3; ++c) out.rgb[c] = at<std::uint16_t>(bytes, p + 30 + 2 * c);
    if (record_length > 36) {
      for (std::size_t f = 0; f < 4; ++f) out.extra[f] = at<float>(bytes, p + 36 + 4 * f);
    }
    return out;
  }
};

TEST(LasExport, TheHeaderFollowsTheSpecification) {
  const ScratchDir dir;
  const Scan scan = wall_scan({512345.1, 5412345.2, 301.3});
  const std::vector<Scan> scans = {scan};
  const ScanGeometry geometry = compute_geometry(scan).geometry;
  const std::vector<const ScanGeometry*> geometry_of = {&geometry};
  const std::vector<std::uint16_t> ids = {7};
  write_las(dir / "wall.las", scans, ids, geometry_of);
  const LasFile las(dir / "wall.las");
  const std::string& b = las.bytes;
  EXPECT_EQ(b.substr(0, 4), "LASF");
  EXPECT_EQ(at<std::uint16_t>(b, 6) & 0x10, 0x10);  // WKT bit, required for formats 6–10
  EXPECT_EQ(b[24], 1);
  EXPECT_EQ(b[25], 4);
  EXPECT_EQ(at<std::uint16_t>(b, 94), 375);  // header size
  EXPECT_EQ(at<std::uint32_t>(b, 100), 1u);  // one VLR
  EXPECT_EQ(b[104], 7);                      // point data record format
  EXPECT_EQ(las.record_length, 36 + 16);     // four float extra bytes
  EXPECT_EQ(las.point_offset, 375u + 54u + 4u * 192u);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(at<std::uint32_t>(b, 107 + 4 * k), 0u);  // legacy
  std::size_t in_model_points = 0;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i)
    in_model_points += in_model(scan, geometry, i);
  EXPECT_EQ(las.points, in_model_points);
  EXPECT_EQ(at<std::uint64_t>(b, 255), in_model_points);  // all first returns
  EXPECT_EQ(b.size(), las.point_offset + las.points * las.record_length);
  EXPECT_EQ(las.scale, Eigen::Vector3d::Constant(1e-4));
  // The extra bytes VLR: LASF_Spec record 4, NormalX … Footprint as floats.
  EXPECT_EQ(std::string(b.data() + 375 + 2), "LASF_Spec");
  EXPECT_EQ(at<std::uint16_t>(b, 375 + 18), 4);
  EXPECT_EQ(at<std::uint16_t>(b, 375 + 20), 4 * 192);
  const char* names[] = {"NormalX", "NormalY", "NormalZ", "Footprint"};
  for (std::size_t f = 0; f < 4; ++f) {
    const std::size_t d = 375 + 54 + 192 * f;
    EXPECT_EQ(b[d + 2], 9) << names[f];  // float
    EXPECT_EQ(std::string(b.data() + d + 4), names[f]);
  }
}

TEST(LasExport, GeoreferencedPointsKeepTheirTenthOfAMillimetre) {
  const ScratchDir dir;
  const std::vector<Scan> scans = {wall_scan({512345.1, 5412345.2, 301.3}),
                                   wall_scan({512355.7, 5412341.9, 300.1})};
  std::vector<ScanGeometry> geometry;
  for (const Scan& s : scans) geometry.push_back(compute_geometry(s).geometry);
  const std::vector<const ScanGeometry*> geometry_of = {&geometry[0], &geometry[1]};
  // The second scan keeps every other point (a merged model).
  std::vector<std::uint8_t> keep(scans[1].pixel_count());
  for (std::size_t i = 0; i < keep.size(); i += 2) keep[i] = 1;
  const std::vector<const std::vector<std::uint8_t>*> keep_of = {nullptr, &keep};
  const std::vector<std::uint16_t> ids = {3, 9};
  write_las(dir / "sites.las", scans, ids, geometry_of, keep_of);
  const LasFile las(dir / "sites.las");
  std::size_t k = 0;
  Eigen::AlignedBox3d box;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const Scan& scan = scans[s];
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.columns; ++col) {
        const std::size_t i = scan.index(row, col);
        if (!in_model(scan, geometry[s], i) || (s == 1 && keep[i] == 0)) continue;
        ASSERT_LT(k, las.points);
        const LasPoint p = las.point(k++);
        const Eigen::Vector3d world = point_in_world(scan, row, col);
        EXPECT_LE((p.position - world).cwiseAbs().maxCoeff(), 0.5e-4 + 1e-9);
        box.extend(p.position);
        EXPECT_EQ(p.intensity, std::lround(scan.intensity[i] * 65535.0f));
        EXPECT_EQ(p.returns, 0x11);  // return 1 of 1
        EXPECT_EQ(p.source, ids[s]);
        for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(p.rgb[c], scan.rgb[3 * i + c] * 257);
        const Eigen::Vector3f n = scan.T_world_scan.linear().cast<float>() * geometry[s].normal[i];
        for (int a = 0; a < 3; ++a) EXPECT_FLOAT_EQ(p.extra[static_cast<std::size_t>(a)], n[a]);
        EXPECT_FLOAT_EQ(p.extra[3], geometry[s].footprint_m[i]);
      }
    }
  }
  EXPECT_EQ(k, las.points);
  // The offset is the minimum corner; the bounds are the stored points'.
  EXPECT_TRUE(las.offset.isApprox(las.min, 1e-12));
  EXPECT_LE((box.min() - las.min).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LE((box.max() - las.max).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(LasExport, WithoutGeometryThereAreNoExtraBytesAndTooWideASiteIsRefused) {
  const ScratchDir dir;
  const std::vector<Scan> one = {wall_scan({0.0, 0.0, 0.0})};
  const std::vector<std::uint16_t> id = {1};
  write_las(dir / "plain.las", one, id);
  const LasFile las(dir / "plain.las");
  EXPECT_EQ(las.record_length, 36);
  EXPECT_EQ(las.point_offset, 375u);
  EXPECT_EQ(at<std::uint32_t>(las.bytes, 100), 0u);
  // 300 km apart: more than 2³¹ tenths of a millimetre.
  const std::vector<Scan> far = {wall_scan({0.0, 0.0, 0.0}), wall_scan({300000.0, 0.0, 0.0})};
  const std::vector<std::uint16_t> ids = {1, 2};
  try {
    write_las(dir / "far.las", far, ids);
    ADD_FAILURE() << "a 300 km site was written";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.problem(), ::testing::HasSubstr("0.1 mm"));
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "far.las"));
}

// Written scan by scan, a LAS takes its offset from bounds given up front
// (a project's stored ones); a point far outside them, beyond what the
// integers hold, is refused naming the scan, and no file is left.
TEST(LasExport, APointBeyondTheGivenBoundsIsRefusedNamingTheScan) {
  const ScratchDir dir;
  PointListWriter::LasSettings las;
  las.bounds = Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-5.0), Eigen::Vector3d::Constant(5.0));
  PointChannels channels;
  channels.geometry = false;
  {
    PointListWriter writer(dir / "stale.las", PointListFormat::kLas, channels, las);
    writer.add(wall_scan({0.0, 0.0, 0.0}), nullptr);
    Scan far = wall_scan({300000.0, 0.0, 0.0});
    far.name = "far station";
    try {
      writer.add(far, nullptr);
      ADD_FAILURE() << "a point 300 km off the bounds was written";
    } catch (const core::InputError& error) {
      EXPECT_THAT(error.what(), ::testing::HasSubstr("far station"));
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "stale.las"));
}

}  // namespace
}  // namespace scanbench::acquisition
