#include "acquisition/formats/triplet_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>

#include "acquisition/formats/image_decoder.hpp"
#include "acquisition/formats/json_input.hpp"
#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"

namespace scanbench::acquisition {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::int64_t kMaxSide = 1'000'000;
constexpr std::int64_t kMaxPixels = std::int64_t{1} << 31;

std::string utf8(const fs::path& path) {
  const std::u8string text = path.u8string();
  return {text.begin(), text.end()};
}

core::FilePosition at_detail(std::string detail) {
  core::FilePosition position;
  position.detail = std::move(detail);
  return position;
}

// Keys are addressed by their dotted path ("angles.azimuth_step_rad") so that
// the message points at the exact spot in the sidecar.
struct Sidecar {
  fs::path path;
  std::string file;  // UTF-8 sidecar path, for messages
  json root;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw core::InputError(file, at_detail("key \"" + key + "\""), problem);
  }
  const json& need(const json& object, const std::string& key, const std::string& path) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(path, "missing required key");
    return *it;
  }
  double number(const json& value, const std::string& path) const {
    if (!value.is_number()) fail(path, "must be a number, not " + std::string(value.type_name()));
    return value.get<double>();  // finite: nlohmann refuses to parse an overflowing literal
  }
  double number(const json& object, const std::string& key, const std::string& path) const {
    return number(need(object, key, path), path);
  }
  std::int64_t integer(const json& object, const std::string& key) const {
    const json& value = need(object, key, key);
    if (!value.is_number_integer()) fail(key, "must be an integer");
    if (value.is_number_unsigned() && value.get<std::uint64_t>() > kMaxPixels)
      return kMaxPixels + 1;
    return value.get<std::int64_t>();
  }
  std::string string(const json& object, const std::string& key, const std::string& path) const {
    const json& value = need(object, key, path);
    if (!value.is_string()) fail(path, "must be a string, not " + std::string(value.type_name()));
    return value.get<std::string>();
  }
  const json& object(const json& parent, const std::string& key) const {
    const json& value = need(parent, key, key);
    if (!value.is_object()) fail(key, "must be an object, not " + std::string(value.type_name()));
    return value;
  }
  template <std::size_t N>
  std::array<double, N> numbers(const std::string& key) const {
    const json& value = need(root, key, key);
    if (!value.is_array() || value.size() != N) {
      fail(key, "must be an array of " + std::to_string(N) + " numbers");
    }
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      out[i] = number(value[i], key + "[" + std::to_string(i) + "]");
    }
    return out;
  }
};

Sidecar parse_sidecar(const fs::path& path) {
  Sidecar sidecar{.path = path, .file = utf8(path), .root = {}};
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::is_regular_file(status)) {
    throw core::InputError(
        sidecar.file, {},
        fs::exists(status) ? "sidecar is not a regular file" : "sidecar file is missing");
  }
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.empty()) throw core::InputError(sidecar.file, {}, "sidecar file is empty or unreadable");
  sidecar.root = parse_json(text, sidecar.file);
  if (!sidecar.root.is_object())
    throw core::InputError(sidecar.file, {}, "sidecar must be a JSON object");
  return sidecar;
}

void check_format(const Sidecar& s) {
  if (s.string(s.root, "format", "format") != "scanbench-triplet") {
    s.fail("format", "unknown format (expected \"scanbench-triplet\")");
  }
  const std::int64_t version = s.integer(s.root, "version");
  if (version != 1) s.fail("version", "unsupported version " + std::to_string(version));
}

struct Grid {
  int rows = 0, columns = 0;
};

Grid read_grid(const Sidecar& s) {
  const std::int64_t rows = s.integer(s.root, "rows");
  const std::int64_t columns = s.integer(s.root, "columns");
  for (const auto& [key, value] : {std::pair{"rows", rows}, std::pair{"columns", columns}}) {
    if (value <= 0) s.fail(key, "must be positive");
    if (value > kMaxSide) s.fail(key, "absurd size (more than 1000000)");
  }
  if (rows * columns > kMaxPixels) s.fail("rows", "absurd size (rows x columns > 2^31)");
  return {static_cast<int>(rows), static_cast<int>(columns)};
}

SphericalAngles read_angles(const Sidecar& s) {
  const json& angles = s.object(s.root, "angles");
  auto get = [&](const char* key) { return s.number(angles, key, std::string("angles.") + key); };
  SphericalAngles out{.azimuth_start_rad = get("azimuth_start_rad"),
                      .azimuth_step_rad = get("azimuth_step_rad"),
                      .elevation_start_rad = get("elevation_start_rad"),
                      .elevation_step_rad = get("elevation_step_rad")};
  if (out.azimuth_step_rad == 0.0) s.fail("angles.azimuth_step_rad", "step must not be zero");
  if (out.elevation_step_rad == 0.0) s.fail("angles.elevation_step_rad", "step must not be zero");
  // Every direction the grid names must be an angle: beyond these, sines and
  // cosines of start + k · step are no longer numbers to trust (1e308 · k is
  // not even finite).
  constexpr double kTurn = 2.0 * std::numbers::pi;
  for (const auto& [key, value] : {std::pair{"azimuth_step_rad", out.azimuth_step_rad},
                                   std::pair{"elevation_step_rad", out.elevation_step_rad}}) {
    if (std::abs(value) > kTurn)
      s.fail(std::string("angles.") + key, "step is more than a full turn");
  }
  for (const auto& [key, value] : {std::pair{"azimuth_start_rad", out.azimuth_start_rad},
                                   std::pair{"elevation_start_rad", out.elevation_start_rad}}) {
    if (std::abs(value) > 2.0 * kTurn) {
      s.fail(std::string("angles.") + key, "start is more than two turns from zero");
    }
  }
  return out;
}

Eigen::Isometry3d read_pose(const Sidecar& s) {
  const Eigen::Matrix4d m = matrix_from_row_major(s.numbers<16>("T_world_scan"));
  if (const std::string problem = rigid_transform_problem(m); !problem.empty()) {
    s.fail("T_world_scan", problem);
  }
  return to_isometry(m);
}

// What the sidecar says about each image, checked before any image is opened.
struct RangeSpec {
  std::string file;
  bool uint16 = false;
  double scale_m = 0.0, offset_m = 0.0;
};
struct ColorSpec {
  std::string file;
  bool srgb = true;
};

RangeSpec read_range_spec(const Sidecar& s) {
  const json& range = s.object(s.root, "range");
  RangeSpec spec{.file = s.string(range, "file", "range.file")};
  const std::string encoding = s.string(range, "encoding", "range.encoding");
  if (encoding == "float32") return spec;
  if (encoding != "uint16") s.fail("range.encoding", "unknown encoding (not float32/uint16)");
  spec.uint16 = true;
  spec.scale_m = s.number(range, "scale_m", "range.scale_m");
  if (spec.scale_m <= 0.0) s.fail("range.scale_m", "scale must be positive");
  if (range.contains("offset_m")) spec.offset_m = s.number(range, "offset_m", "range.offset_m");
  return spec;
}

std::optional<std::string> read_intensity_spec(const Sidecar& s) {
  if (!s.root.contains("intensity")) return std::nullopt;
  return s.string(s.object(s.root, "intensity"), "file", "intensity.file");
}

std::optional<ColorSpec> read_color_spec(const Sidecar& s) {
  if (!s.root.contains("color")) return std::nullopt;
  const json& color = s.object(s.root, "color");
  ColorSpec spec{.file = s.string(color, "file", "color.file")};
  if (color.contains("transfer")) {
    const std::string transfer = s.string(color, "transfer", "color.transfer");
    if (transfer != "srgb" && transfer != "linear") {
      s.fail("color.transfer", "unknown transfer (expected srgb or linear)");
    }
    spec.srgb = transfer == "srgb";
  }
  return spec;
}

std::string describe(const cv::Mat& image) {
  // Indexed by OpenCV depth: CV_8U = 0 … CV_16F = 7.
  static const char* const kDepths[] = {"8-bit",      "8-bit signed", "16-bit", "16-bit signed",
                                        "32-bit int", "float",        "double", "half float"};
  return std::string(kDepths[image.depth()]) + ", " + std::to_string(image.channels()) +
         " channel(s)";
}

// Loads one image named by `key` ("range", ...) and checks its grid size; the
// caller checks the pixel type because each channel accepts different ones.
struct Image {
  std::filesystem::path path;
  std::string file;  // UTF-8 path, for messages
  cv::Mat pixels;
};

Image load_image(const Sidecar& s, const std::string& name, const std::string& key, Grid grid) {
  const fs::path path = s.path.parent_path() / fs::path(std::u8string(name.begin(), name.end()));
  Image image{.path = path, .file = utf8(path), .pixels = {}};
  const core::FilePosition where = at_detail("named by key \"" + key + ".file\" of the sidecar");
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (error && error != std::errc::no_such_file_or_directory) {
    // ENAMETOOLONG and the like: the name in the sidecar is the problem.
    s.fail(key + ".file", "cannot be an image file name (" + error.message() + ")");
  }
  if (!fs::exists(status)) throw core::InputError(image.file, where, "image file is missing");
  if (!fs::is_regular_file(status)) {
    throw core::InputError(image.file, where,
                           fs::is_directory(status) ? "is a directory, not an image file"
                                                    : "is not a regular file (a pipe or a device)");
  }
  DecodedImage decoded = decode_image(path, grid.rows, grid.columns);
  if (decoded.pixels.empty()) throw core::InputError(image.file, where, decoded.problem);
  image.pixels = std::move(decoded.pixels);
  return image;
}

void require_type(const Image& image, bool ok, const std::string& expected) {
  if (ok) return;
  throw core::InputError(image.file, {},
                         "wrong image type: " + describe(image.pixels) + ", expected " + expected);
}

void decode_range(const Image& image, const RangeSpec& spec, Scan& scan) {
  const cv::Mat& m = image.pixels;
  for (int row = 0; row < m.rows; ++row) {
    for (int col = 0; col < m.cols; ++col) {
      float range = 0.0f;
      if (!spec.uint16) {
        range = m.ptr<float>(row)[col];
      } else if (const std::uint16_t v = m.ptr<std::uint16_t>(row)[col]; v != 0) {
        range = static_cast<float>(spec.offset_m + spec.scale_m * v);
      }
      const bool valid = std::isfinite(range) && range > 0.0f;
      scan.range_m[scan.index(row, col)] = valid ? range : 0.0f;
      scan.valid[scan.index(row, col)] = valid ? 1 : 0;
    }
  }
}

void decode_intensity(const Image& image, Scan& scan) {
  const cv::Mat& m = image.pixels;
  const bool is16 = m.depth() == CV_16U;
  for (int row = 0; row < m.rows; ++row) {
    for (int col = 0; col < m.cols; ++col) {
      scan.intensity[scan.index(row, col)] =
          is16 ? static_cast<float>(m.ptr<std::uint16_t>(row)[col]) / 65535.0f
               : static_cast<float>(m.ptr<std::uint8_t>(row)[col]) / 255.0f;
    }
  }
}

using TransferTable = std::array<std::uint8_t, 65536>;

// One table per curve, built on first use: a pow() per channel sample would
// dominate the read time of a 10-megapixel panorama.
const TransferTable& transfer_table(bool srgb) {
  static const auto build = [](bool use_srgb) {
    TransferTable table{};
    for (std::size_t v = 0; v < table.size(); ++v) {
      const double x = static_cast<double>(v) / 65535.0;
      const double y = x < 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
      const double out = use_srgb ? 255.0 * y : static_cast<double>(v) / 257.0;
      table[v] = static_cast<std::uint8_t>(std::lround(std::clamp(out, 0.0, 255.0)));
    }
    return table;
  };
  static const TransferTable srgb_table = build(true);
  static const TransferTable linear_table = build(false);
  return srgb ? srgb_table : linear_table;
}

void decode_color(const Image& image, const ColorSpec& spec, Scan& scan) {
  const cv::Mat& m = image.pixels;
  const int channels = m.channels();
  const TransferTable& table = transfer_table(spec.srgb);
  for (int row = 0; row < m.rows; ++row) {
    for (int col = 0; col < m.cols; ++col) {
      std::uint8_t* rgb = &scan.rgb[3 * scan.index(row, col)];
      for (int c = 0; c < 3; ++c) {
        // OpenCV stores B, G, R; the scan stores R, G, B.
        const std::size_t sample = static_cast<std::size_t>(col) * channels + (2 - c);
        rgb[c] = m.depth() == CV_16U ? table[m.ptr<std::uint16_t>(row)[sample]]
                                     : m.ptr<std::uint8_t>(row)[sample];
      }
    }
  }
}

Eigen::Vector3d read_position(const Sidecar& s, const Eigen::Isometry3d& pose) {
  if (!s.root.contains("scanner_position_world")) return pose.translation();
  const auto xyz = s.numbers<3>("scanner_position_world");
  return {xyz[0], xyz[1], xyz[2]};
}

std::string optional_string(const Sidecar& s, const char* key, std::string fallback) {
  return s.root.contains(key) ? s.string(s.root, key, key) : fallback;
}

struct Channels {
  RangeSpec range_spec;
  std::optional<ColorSpec> color_spec;
  Image range;
  std::optional<Image> intensity;
  std::optional<Image> color;
};

// Every image is loaded and type-checked before the scan is allocated, so bad
// input never costs a full-size allocation.
Channels load_channels(const Sidecar& s, Grid grid) {
  Channels out;
  out.range_spec = read_range_spec(s);
  out.color_spec = read_color_spec(s);
  const std::optional<std::string> intensity_file = read_intensity_spec(s);
  const bool uint16 = out.range_spec.uint16;
  out.range = load_image(s, out.range_spec.file, "range", grid);
  require_type(
      out.range, out.range.pixels.type() == (uint16 ? CV_16UC1 : CV_32FC1),
      uint16 ? "16-bit, 1 channel (uint16 encoding)" : "float, 1 channel (float32 encoding)");
  if (intensity_file) {
    out.intensity = load_image(s, *intensity_file, "intensity", grid);
    const int depth = out.intensity->pixels.depth();
    require_type(*out.intensity,
                 out.intensity->pixels.channels() == 1 && (depth == CV_8U || depth == CV_16U),
                 "8 or 16-bit, 1 channel");
  }
  if (out.color_spec) {
    out.color = load_image(s, out.color_spec->file, "color", grid);
    const int depth = out.color->pixels.depth();
    const int channels = out.color->pixels.channels();
    require_type(*out.color,
                 (channels == 3 || channels == 4) && (depth == CV_8U || depth == CV_16U),
                 "8 or 16-bit, 3 channels (or 4 with alpha)");
  }
  return out;
}

}  // namespace

Scan read_triplet(const std::filesystem::path& sidecar_json,
                  std::vector<std::filesystem::path>* image_files) {
  const Sidecar s = parse_sidecar(sidecar_json);
  check_format(s);
  const Grid grid = read_grid(s);
  const SphericalAngles angles = read_angles(s);
  const Eigen::Isometry3d pose = read_pose(s);
  const Eigen::Vector3d position = read_position(s, pose);
  const std::string name = optional_string(s, "name", utf8(sidecar_json.stem()));
  const std::string scanner = optional_string(s, "scanner", "");
  // Decoded images (up to 8 bytes a pixel each, three of them) and the scan.
  core::check_memory(static_cast<std::uint64_t>(grid.rows) * grid.columns * 40, s.file);
  const Channels channels = load_channels(s, grid);
  Scan scan = make_empty_scan(grid.rows, grid.columns, channels.intensity.has_value(),
                              channels.color.has_value());
  decode_range(channels.range, channels.range_spec, scan);
  if (channels.intensity) decode_intensity(*channels.intensity, scan);
  if (channels.color) decode_color(*channels.color, *channels.color_spec, scan);
  scan.name = name;
  scan.angles = angles;
  scan.T_world_scan = pose;
  scan.scanner =
      ScannerMetadata{.name = scanner, .source_file = s.file, .position_world = position};
  if (image_files != nullptr) {
    image_files->push_back(channels.range.path);
    if (channels.intensity) image_files->push_back(channels.intensity->path);
    if (channels.color) image_files->push_back(channels.color->path);
  }
  return scan;
}

}  // namespace scanbench::acquisition
