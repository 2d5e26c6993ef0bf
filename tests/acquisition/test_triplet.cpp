#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "acquisition/formats/triplet_reader.hpp"
#include "acquisition/formats/triplet_writer.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using test::fixture;
using test::ScratchDir;

// Netpbm and PFM are the simplest image files OpenCV reads; the tests write
// them byte by byte because they do not link OpenCV themselves.
std::string netpbm(const char* magic, int rows, int cols, int maxval, const std::vector<int>& v) {
  std::string out = std::string(magic) + "\n" + std::to_string(cols) + " " + std::to_string(rows) +
                    "\n" + std::to_string(maxval) + "\n";
  for (const int sample : v) {
    if (maxval > 255) out += static_cast<char>(sample >> 8);  // 16-bit samples are big-endian
    out += static_cast<char>(sample & 0xff);
  }
  return out;
}

std::string pfm(const char* magic, int rows, int cols, const std::vector<float>& v) {
  std::string out = std::string(magic) + "\n" + std::to_string(cols) + " " + std::to_string(rows) +
                    "\n-1.0\n";  // negative scale: little-endian
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(float));
  return out;
}

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

nlohmann::json read_json(const std::filesystem::path& path) {
  return nlohmann::json::parse(test::read_file_bytes(path));
}

void write_json(const std::filesystem::path& path, const nlohmann::json& j) {
  write_bytes(path, j.dump(2));
}

// 2 × 3 scan with every channel and a rotated, offset pose.
Scan make_scan() {
  Scan scan = make_empty_scan(2, 3, true, true);
  scan.name = "hall é";
  scan.range_m = {1.0f / 3.0f, 0.0f, 123456.789f, 1e-3f, 42.0f, 7.25f};
  scan.valid = {1, 0, 1, 1, 1, 1};
  scan.intensity = {0.0f, 0.1f, 0.5f, 1.0f, 0.25f, 0.999f};
  for (std::size_t i = 0; i < scan.rgb.size(); ++i) scan.rgb[i] = static_cast<std::uint8_t>(i * 13);
  scan.angles = SphericalAngles{0.1, 0.0123456789, -0.7, 0.00314159};
  scan.T_world_scan = Eigen::Translation3d(512345.125, 5412345.5, 210.75) *
                      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  scan.scanner.name = "RIEGL LMS-Z360";
  scan.scanner.position_world = Eigen::Vector3d(512345.125, 5412345.5, 212.0);
  return scan;
}

void expect_same_scan(const Scan& a, const Scan& b) {
  EXPECT_EQ(a.rows, b.rows);
  EXPECT_EQ(a.columns, b.columns);
  EXPECT_EQ(a.range_m, b.range_m);
  EXPECT_EQ(a.valid, b.valid);
  EXPECT_EQ(a.intensity, b.intensity);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_TRUE(a.angles == b.angles);
  EXPECT_EQ(a.T_world_scan.matrix(), b.T_world_scan.matrix());
  EXPECT_EQ(a.scanner.position_world, b.scanner.position_world);
  EXPECT_EQ(a.scanner.name, b.scanner.name);
  EXPECT_EQ(a.name, b.name);
}

TEST(TripletReader, ReadsHandBuiltUint16TripletWithExactValues) {
  const Scan scan = read_triplet(fixture("good/triplet/small.json"));
  ASSERT_EQ(scan.rows, 2);
  ASSERT_EQ(scan.columns, 3);
  const std::vector<std::uint16_t> counts = {0, 1000, 2000, 65535, 1, 1500};
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const float expected = counts[i] == 0 ? 0.0f : static_cast<float>(0.5 + 0.001 * counts[i]);
    EXPECT_EQ(scan.range_m[i], expected) << "pixel " << i;
    EXPECT_EQ(scan.valid[i], counts[i] == 0 ? 0 : 1) << "pixel " << i;
  }
  EXPECT_EQ(scan.intensity,
            (std::vector<float>{0.0f, 51 / 255.0f, 1.0f, 128 / 255.0f, 1 / 255.0f, 254 / 255.0f}));
  // R, G, B order, although OpenCV hands the file over as B, G, R.
  EXPECT_EQ(scan.rgb, (std::vector<std::uint8_t>{255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30, 200,
                                                 100, 50, 0, 0, 0}));
  EXPECT_TRUE(scan.angles == (AngleModel{SphericalAngles{0.1, 0.01, 0.5, -0.02}}));
  Eigen::Matrix4d pose;
  pose << 0, -1, 0, 1000.5, 1, 0, 0, -2000.25, 0, 0, 1, 3.125, 0, 0, 0, 1;
  EXPECT_EQ(scan.T_world_scan.matrix(), pose);
  EXPECT_EQ(scan.name, "lobby");
  EXPECT_EQ(scan.scanner.name, "RIEGL LMS-Z360");
  EXPECT_EQ(scan.scanner.position_world, Eigen::Vector3d(1000.5, -2000.25, 4.625));
  EXPECT_NE(scan.scanner.source_file.find("small.json"), std::string::npos);
}

TEST(TripletReader, NameDefaultsToStemAndPositionToPoseTranslation) {
  const ScratchDir dir;
  const auto sidecar = dir / "stem ü.json";
  write_triplet(make_scan(), sidecar);
  nlohmann::json j = read_json(sidecar);
  j.erase("name");
  j.erase("scanner");
  j.erase("scanner_position_world");
  write_json(sidecar, j);
  const Scan scan = read_triplet(sidecar);
  EXPECT_EQ(scan.name, "stem ü");
  EXPECT_EQ(scan.scanner.name, "");
  EXPECT_EQ(scan.scanner.position_world, make_scan().T_world_scan.translation());
}

// Writes a good triplet, then points `key` at an image made of `bytes`.
std::filesystem::path triplet_with_image(const ScratchDir& dir, const std::string& key,
                                         const std::string& file, const std::string& bytes) {
  const auto sidecar = dir / "scan.json";
  write_triplet(make_scan(), sidecar);
  write_bytes(dir / file, bytes);
  nlohmann::json j = read_json(sidecar);
  j[key]["file"] = file;
  write_json(sidecar, j);
  return sidecar;
}

TEST(TripletReader, Maps16BitColorThroughTheSrgbCurve) {
  const ScratchDir dir;
  // R, G, B samples in file order; known 8-bit results computed from IEC 61966-2-1.
  const std::vector<int> samples = {0, 100, 13107, 32768, 65535, 205};
  const auto sidecar =
      triplet_with_image(dir, "color", "c.ppm", netpbm("P6", 1, 2, 65535, samples));
  nlohmann::json j = read_json(sidecar);
  j["rows"] = 1;
  j["columns"] = 2;
  j["range"] = {{"file", "r.pfm"}, {"encoding", "float32"}};
  j.erase("intensity");
  write_json(sidecar, j);
  write_bytes(dir / "r.pfm", pfm("Pf", 1, 2, {1.0f, 2.0f}));
  EXPECT_EQ(read_triplet(sidecar).rgb, (std::vector<std::uint8_t>{0, 5, 124, 188, 255, 10}));
  j["color"]["transfer"] = "linear";
  write_json(sidecar, j);
  write_bytes(dir / "c.ppm", netpbm("P6", 1, 2, 65535, {128, 129, 385, 386, 65535, 257 * 77}));
  EXPECT_EQ(read_triplet(sidecar).rgb, (std::vector<std::uint8_t>{0, 1, 1, 2, 255, 77}));
}

TEST(TripletReader, Scales16BitIntensityToUnitRange) {
  const ScratchDir dir;
  const auto sidecar = triplet_with_image(dir, "intensity", "i.pgm",
                                          netpbm("P5", 2, 3, 65535, {0, 1, 32768, 65535, 2, 3}));
  const Scan scan = read_triplet(sidecar);
  EXPECT_EQ(scan.intensity, (std::vector<float>{0.0f, 1 / 65535.0f, 32768 / 65535.0f, 1.0f,
                                                2 / 65535.0f, 3 / 65535.0f}));
}

TEST(TripletReader, Float32RangeTreatsNanInfAndNonPositiveAsNoReturn) {
  const ScratchDir dir;
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto sidecar = triplet_with_image(dir, "range", "r.pfm",
                                          pfm("Pf", 1, 6, {nan, inf, -1.0f, 0.0f, 2.5f, -inf}));
  nlohmann::json j = read_json(sidecar);
  j["rows"] = 1;
  j["columns"] = 6;
  j.erase("intensity");
  j.erase("color");
  write_json(sidecar, j);
  const Scan scan = read_triplet(sidecar);
  EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{0, 0, 0, 0, 1, 0}));
  EXPECT_EQ(scan.range_m, (std::vector<float>{0, 0, 0, 0, 2.5f, 0}));
}

TEST(TripletRoundTrip, WriteThenReadFloat32IsExact) {
  const ScratchDir dir;
  const Scan scan = make_scan();
  write_triplet(scan, dir / "scan.json");
  EXPECT_TRUE(std::filesystem::exists(dir / "scan_range.tiff"));
  EXPECT_TRUE(std::filesystem::exists(dir / "scan_intensity.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "scan_color.png"));
  Scan back = read_triplet(dir / "scan.json");
  Scan expected = scan;
  // Intensity goes through 16 bits.
  for (float& i : expected.intensity) i = static_cast<float>(std::lround(i * 65535.0)) / 65535.0f;
  expect_same_scan(back, expected);
}

TEST(TripletRoundTrip, WriteThenReadUint16RoundsToTheScale) {
  const ScratchDir dir;
  Scan scan = make_scan();
  scan.range_m = {1.2344f, 0.0f, 60.0f, 0.501f, 42.0f, 7.25f};
  TripletWriteSettings settings;
  settings.range_encoding = TripletWriteSettings::RangeEncoding::kUint16;
  settings.range_offset_m = 0.5;
  write_triplet(scan, dir / "scan.json", settings);
  const Scan back = read_triplet(dir / "scan.json");
  const std::vector<int> counts = {734, 0, 59500, 1, 41500, 6750};
  for (std::size_t i = 0; i < counts.size(); ++i) {
    EXPECT_EQ(back.range_m[i], counts[i] ? static_cast<float>(0.5 + 0.001 * counts[i]) : 0.0f);
  }
  EXPECT_EQ(back.valid, scan.valid);
}

TEST(TripletRoundTrip, ReadWriteReadIsBitIdenticalForBothEncodings) {
  const Scan first = read_triplet(fixture("good/triplet/small.json"));
  TripletWriteSettings uint16;
  uint16.range_encoding = TripletWriteSettings::RangeEncoding::kUint16;
  uint16.range_offset_m = 0.5;
  for (const TripletWriteSettings& settings : {TripletWriteSettings{}, uint16}) {
    const ScratchDir dir;
    write_triplet(first, dir / "copy.json", settings);
    expect_same_scan(read_triplet(dir / "copy.json"), first);
  }
}

TEST(TripletWriter, RejectsScanWithPerPixelDirections) {
  const ScratchDir dir;
  Scan scan = make_scan();
  scan.angles = PerPixelDirections{std::vector<Eigen::Vector3f>(6, Eigen::Vector3f::UnitX())};
  EXPECT_THROW(write_triplet(scan, dir / "scan.json"), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "scan.json"));
}

TEST(TripletWriter, RejectsRangeThatDoesNotFitUint16AndWritesNothing) {
  const ScratchDir dir;
  TripletWriteSettings settings;
  settings.range_encoding = TripletWriteSettings::RangeEncoding::kUint16;  // 65.535 m at most
  EXPECT_THROW(write_triplet(make_scan(), dir / "scan.json", settings), std::invalid_argument);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(TripletWriter, ReportsUnwritableFolderNamingTheFile) {
  const ScratchDir dir;
  try {
    write_triplet(make_scan(), dir / "no such folder" / "scan.json");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("scan_range.tiff"), std::string::npos) << e.what();
  }
}

// ---- malformed sidecars: one fixture each -------------------------------

struct BadSidecar {
  const char* fixture;     // fixtures/bad/<fixture>.json
  const char* named_file;  // must appear in the message
  const char* problem;     // word(s) describing the problem
};

class TripletBadSidecar : public testing::TestWithParam<BadSidecar> {};

TEST_P(TripletBadSidecar, ThrowsInputErrorNamingFileAndProblem) {
  const BadSidecar& c = GetParam();
  try {
    read_triplet(fixture(std::string("bad/") + c.fixture + ".json"));
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(c.named_file), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find(c.problem), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TripletBadSidecar,
    testing::Values(
        BadSidecar{"triplet_empty", "triplet_empty.json", "empty"},
        BadSidecar{"triplet_not_json", "triplet_not_json.json", "not valid JSON"},
        BadSidecar{"triplet_top_level_array", "triplet_top_level_array.json", "object"},
        BadSidecar{"triplet_missing_angles", "key \"angles\"", "missing required key"},
        BadSidecar{"triplet_missing_azimuth_step", "key \"angles.azimuth_step_rad\"", "missing"},
        BadSidecar{"triplet_rows_wrong_type", "key \"rows\"", "integer"},
        BadSidecar{"triplet_angles_wrong_type", "key \"angles\"", "must be an object"},
        BadSidecar{"triplet_transform_wrong_length", "key \"T_world_scan\"", "16 numbers"},
        BadSidecar{"triplet_wrong_format", "key \"format\"", "unknown format"},
        BadSidecar{"triplet_wrong_version", "key \"version\"", "unsupported version 2"},
        BadSidecar{"triplet_zero_rows", "key \"rows\"", "positive"},
        BadSidecar{"triplet_negative_columns", "key \"columns\"", "positive"},
        BadSidecar{"triplet_absurd_rows", "key \"rows\"", "absurd"},
        BadSidecar{"triplet_absurd_pixel_count", "triplet_absurd_pixel_count.json", "absurd"},
        BadSidecar{"triplet_missing_image", "triplet_missing_range.png", "missing"},
        BadSidecar{"triplet_nonrigid_transform", "key \"T_world_scan\"", "not rigid"},
        BadSidecar{"triplet_nonfinite_transform", "triplet_nonfinite_transform.json", "not finite"},
        BadSidecar{"triplet_nonfinite_angle", "triplet_nonfinite_angle.json", "not finite"},
        BadSidecar{"triplet_zero_step", "key \"angles.elevation_step_rad\"", "zero"},
        BadSidecar{"triplet_huge_step", "key \"angles.azimuth_step_rad\"", "full turn"},
        BadSidecar{"triplet_start_beyond_two_turns", "key \"angles.elevation_start_rad\"",
                   "more than two turns"},
        BadSidecar{"triplet_long_image_name", "key \"range.file\"", "file name"},
        BadSidecar{"triplet_zero_scale", "key \"range.scale_m\"", "positive"},
        BadSidecar{"triplet_negative_scale", "key \"range.scale_m\"", "positive"},
        BadSidecar{"triplet_nonfinite_scale", "triplet_nonfinite_scale.json", "not finite"},
        BadSidecar{"triplet_unknown_encoding", "key \"range.encoding\"", "unknown encoding"},
        BadSidecar{"triplet_unknown_transfer", "key \"color.transfer\"", "unknown transfer"}),
    [](const testing::TestParamInfo<BadSidecar>& info) {
      return std::string(info.param.fixture).substr(std::strlen("triplet_"));
    });

TEST(TripletReader, NotJsonReportsTheParserByteOffset) {
  try {
    read_triplet(fixture("bad/triplet_not_json.json"));
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    ASSERT_TRUE(e.position().byte_offset.has_value()) << e.what();
    EXPECT_EQ(*e.position().byte_offset, 57u) << e.what();  // the 'o' of "oops"
  }
}

TEST(TripletReader, MissingSidecarIsAnInputError) {
  const ScratchDir dir;
  EXPECT_THROW(read_triplet(dir / "nothing here.json"), core::InputError);
}

// A little-endian, uncompressed TIFF of grey 32-bit float samples that
// declares `rows` × `cols`; `samples` (row by row) are stored in one strip,
// or in one 16 × 16 tile when `tiled`. With no samples, only the header.
std::string float_tiff(std::uint32_t rows, std::uint32_t cols, const std::vector<float>& samples,
                       bool tiled = false) {
  std::vector<float> data = samples;
  if (tiled && !samples.empty()) {
    data.assign(16 * 16, 0.0f);
    for (std::uint32_t r = 0; r < rows; ++r)
      for (std::uint32_t c = 0; c < cols; ++c) data[r * 16 + c] = samples[r * cols + c];
  }
  const std::uint16_t entries = tiled ? 11 : 10;
  const std::uint32_t data_offset = 8 + 2 + 12u * entries + 4;
  const auto data_bytes = static_cast<std::uint32_t>(data.size() * sizeof(float));
  std::string out = {'I', 'I', 42, 0, 8, 0, 0, 0};
  auto put16 = [&out](std::uint16_t v) { out.append(reinterpret_cast<const char*>(&v), 2); };
  auto put32 = [&out](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  auto entry = [&](std::uint16_t tag, std::uint16_t type, std::uint32_t value) {
    put16(tag);
    put16(type);
    put32(1);
    type == 3 ? (put16(static_cast<std::uint16_t>(value)), put16(0)) : put32(value);
  };
  put16(entries);  // tags in ascending order; type 3 SHORT, 4 LONG
  entry(256, 4, cols);
  entry(257, 4, rows);
  entry(258, 3, 32);  // bits per sample
  entry(259, 3, 1);   // no compression
  entry(262, 3, 1);   // grey, black is zero
  if (!tiled) entry(273, 4, data_offset);
  entry(277, 3, 1);  // samples per pixel
  if (!tiled) {
    entry(278, 4, rows);  // rows per strip
    entry(279, 4, data_bytes);
  } else {
    entry(322, 3, 16);
    entry(323, 3, 16);
    entry(324, 4, data_offset);
    entry(325, 4, data_bytes);
  }
  entry(339, 3, 3);  // IEEE float samples
  put32(0);          // no further image
  out.append(reinterpret_cast<const char*>(data.data()), data_bytes);
  return out;
}

TEST(TripletReader, ReadsFloatTiffsInStripsAndTilesAndPfmFromTheBottomUp) {
  const std::vector<float> values = {1.5f, 2.5f, 3.5f, 4.5f, 5.5f, 6.5f};
  // PFM stores the bottom row first.
  const std::vector<float> bottom_up = {4.5f, 5.5f, 6.5f, 1.5f, 2.5f, 3.5f};
  for (const auto& [file, bytes] :
       {std::pair<std::string, std::string>{"r.tif", float_tiff(2, 3, values)},
        {"r.tif", float_tiff(2, 3, values, true)},
        {"r.pfm", pfm("Pf", 2, 3, bottom_up)}}) {
    const ScratchDir dir;
    const auto sidecar = triplet_with_image(dir, "range", file, bytes);
    nlohmann::json j = read_json(sidecar);
    j["range"]["encoding"] = "float32";
    write_json(sidecar, j);
    EXPECT_EQ(read_triplet(sidecar).range_m, values) << file;
  }
}

TEST(TripletReader, ImageSizeIsCheckedFromTheHeaderBeforeDecoding) {
  // 30000 × 30000 floats would be 3.6 GB; a 90-byte file must not get them.
  for (const auto& [file, bytes] :
       {std::pair<std::string, std::string>{"r.tif", float_tiff(30000, 30000, {})},
        {"r.pfm", "Pf\n30000 30000\n-1.0\n"}}) {
    const ScratchDir dir;
    const auto sidecar = triplet_with_image(dir, "range", file, bytes);
    try {
      read_triplet(sidecar);
      FAIL() << "expected core::InputError for " << file;
    } catch (const core::InputError& e) {
      EXPECT_NE(e.file().find(file), std::string::npos) << e.what();
      EXPECT_NE(e.problem().find("image size 30000 x 30000 differs from the sidecar's 2 x 3"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(TripletReader, TruncatedTiffAndUnknownFormatsAreUnreadable) {
  const std::string tiff = float_tiff(2, 3, {});
  for (const auto& [file, bytes, reason] :
       {std::tuple<std::string, std::string, std::string>{"r.tif", tiff.substr(0, 20), "TIFF"},
        {"r.tif", tiff, "libtiff"},  // the strip lies past the end of the file
        {"r.jpg", "\xff\xd8\xff\xe0 not really a JPEG", "not a PNG, TIFF or PNM image"}}) {
    const ScratchDir dir;
    const auto sidecar = triplet_with_image(dir, "range", file, bytes);
    try {
      read_triplet(sidecar);
      FAIL() << "expected core::InputError for " << file;
    } catch (const core::InputError& e) {
      EXPECT_NE(e.problem().find("unreadable"), std::string::npos) << e.what();
      EXPECT_NE(e.problem().find(reason), std::string::npos) << e.what();
    }
  }
}

// ---- malformed images: one fixture folder each -------------------------

struct BadImage {
  const char* name;     // fixtures/bad/triplet_image_<name>/scan.json
  const char* file;     // the bad image the sidecar names; must appear in e.file()
  const char* problem;  // word(s) describing the problem
};

class TripletBadImage : public testing::TestWithParam<BadImage> {};

TEST_P(TripletBadImage, ThrowsInputErrorNamingTheImage) {
  const BadImage& c = GetParam();
  try {
    read_triplet(fixture(std::string("bad/triplet_image_") + c.name + "/scan.json"));
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(e.file().find(c.file), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find(c.problem), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TripletBadImage,
    testing::Values(BadImage{"corrupt_png", "bad.png", "unreadable"},
                    BadImage{"empty_image_file", "empty.png", "unreadable"},
                    BadImage{"missing_intensity_image", "gone.png", "missing"},
                    BadImage{"range_8bit", "r.pgm", "wrong image type"},
                    BadImage{"range_3_channels", "r.ppm", "wrong image type"},
                    BadImage{"range_float_image_for_uint16", "r.pfm", "wrong image type"},
                    BadImage{"color_grayscale", "c.pgm", "wrong image type"},
                    BadImage{"color_32bit_float", "c.pfm", "wrong image type"},
                    BadImage{"intensity_3_channels", "i.ppm", "wrong image type"},
                    BadImage{"intensity_32bit_float", "i.pfm", "wrong image type"},
                    BadImage{"size_mismatch", "i.pgm", "differs"}),
    [](const testing::TestParamInfo<BadImage>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace scanbench::acquisition
