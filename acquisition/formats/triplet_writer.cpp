#include "acquisition/formats/triplet_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/formats/image_file.hpp"
#include "acquisition/formats/output_file.hpp"
#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;  // keeps the documented key order for people reading it
using Encoding = TripletWriteSettings::RangeEncoding;

std::string utf8(const fs::path& path) {
  const std::u8string text = path.u8string();
  return {text.begin(), text.end()};
}

fs::path from_utf8(const std::string& text) {
  return fs::path(std::u8string(text.begin(), text.end()));
}

[[noreturn]] void reject(const std::string& problem) {
  throw std::invalid_argument("write_triplet: " + problem);
}

void check_writable(const Scan& scan, const TripletWriteSettings& settings) {
  const auto* angles = std::get_if<SphericalAngles>(&scan.angles);
  if (angles == nullptr) reject("the triplet format has only the spherical angle model");
  if (const std::string problem = check_consistency(scan); !problem.empty()) reject(problem);
  if (scan.rows <= 0 || scan.columns <= 0) reject("the scan is empty");
  const bool finite =
      std::isfinite(angles->azimuth_start_rad) && std::isfinite(angles->azimuth_step_rad) &&
      std::isfinite(angles->elevation_start_rad) && std::isfinite(angles->elevation_step_rad);
  if (!finite || angles->azimuth_step_rad == 0.0 || angles->elevation_step_rad == 0.0) {
    reject("angles must be finite with non-zero steps");
  }
  if (const std::string problem = rigid_transform_problem(scan.T_world_scan.matrix());
      !problem.empty()) {
    reject(problem);
  }
  if (!scan.scanner.position_world.allFinite()) reject("scanner position is not finite");
  if (settings.range_encoding == Encoding::kUint16 &&
      !(std::isfinite(settings.range_scale_m) && settings.range_scale_m > 0.0 &&
        std::isfinite(settings.range_offset_m))) {
    reject("uint16 range needs a finite scale > 0 and a finite offset");
  }
}

bool has_range(const Scan& scan, std::size_t i) {
  return scan.valid[i] != 0 && std::isfinite(scan.range_m[i]) && scan.range_m[i] > 0.0f;
}

cv::Mat encode_range_float(const Scan& scan) {
  cv::Mat image(scan.rows, scan.columns, CV_32FC1);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      image.ptr<float>(row)[col] = has_range(scan, i) ? scan.range_m[i] : 0.0f;
    }
  }
  return image;
}

cv::Mat encode_range_uint16(const Scan& scan, const TripletWriteSettings& settings) {
  cv::Mat image(scan.rows, scan.columns, CV_16UC1);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      double count = 0.0;
      if (has_range(scan, i)) {
        count = std::round((scan.range_m[i] - settings.range_offset_m) / settings.range_scale_m);
        if (!(count >= 1.0 && count <= 65535.0)) {
          reject("range " + std::to_string(scan.range_m[i]) + " m at (row " + std::to_string(row) +
                 ", col " + std::to_string(col) + ") does not fit the uint16 encoding");
        }
      }
      image.ptr<std::uint16_t>(row)[col] = static_cast<std::uint16_t>(count);
    }
  }
  return image;
}

cv::Mat encode_intensity(const Scan& scan) {
  cv::Mat image(scan.rows, scan.columns, CV_16UC1);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const float i = scan.intensity[scan.index(row, col)];
      const double clamped = i > 0.0f ? std::min(static_cast<double>(i), 1.0) : 0.0;  // NaN -> 0
      image.ptr<std::uint16_t>(row)[col] =
          static_cast<std::uint16_t>(std::lround(clamped * 65535.0));
    }
  }
  return image;
}

cv::Mat encode_color(const Scan& scan) {
  cv::Mat image(scan.rows, scan.columns, CV_8UC3);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::uint8_t* rgb = &scan.rgb[3 * scan.index(row, col)];
      std::uint8_t* bgr = image.ptr<std::uint8_t>(row) + 3 * col;
      bgr[0] = rgb[2];
      bgr[1] = rgb[1];
      bgr[2] = rgb[0];
    }
  }
  return image;
}

Json range_entry(const std::string& file, const TripletWriteSettings& settings) {
  if (settings.range_encoding == Encoding::kFloat32) {
    return Json{{"file", file}, {"encoding", "float32"}};
  }
  return Json{{"file", file},
              {"encoding", "uint16"},
              {"scale_m", settings.range_scale_m},
              {"offset_m", settings.range_offset_m}};
}

Json make_sidecar(const Scan& scan, const std::string& stem, const TripletWriteSettings& settings) {
  const bool float32 = settings.range_encoding == Encoding::kFloat32;
  const auto& angles = std::get<SphericalAngles>(scan.angles);
  const Eigen::Vector3d& position = scan.scanner.position_world;
  Json root{{"format", "scanbench-triplet"}, {"version", 1},      {"name", scan.name},
            {"scanner", scan.scanner.name},  {"rows", scan.rows}, {"columns", scan.columns}};
  root["range"] = range_entry(stem + (float32 ? "_range.tiff" : "_range.png"), settings);
  if (scan.has_intensity()) root["intensity"] = Json{{"file", stem + "_intensity.png"}};
  if (scan.has_color()) root["color"] = Json{{"file", stem + "_color.png"}, {"transfer", "srgb"}};
  root["angles"] = Json{{"azimuth_start_rad", angles.azimuth_start_rad},
                        {"azimuth_step_rad", angles.azimuth_step_rad},
                        {"elevation_start_rad", angles.elevation_start_rad},
                        {"elevation_step_rad", angles.elevation_step_rad}};
  root["T_world_scan"] = row_major(scan.T_world_scan);
  root["scanner_position_world"] = Json::array({position.x(), position.y(), position.z()});
  return root;
}

}  // namespace

void write_triplet(const Scan& scan, const std::filesystem::path& sidecar_json,
                   const TripletWriteSettings& settings) {
  check_writable(scan, settings);
  const bool float32 = settings.range_encoding == Encoding::kFloat32;
  // Encode everything first: an unencodable range must not leave half a triplet.
  const cv::Mat range = float32 ? encode_range_float(scan) : encode_range_uint16(scan, settings);
  const std::string stem = utf8(sidecar_json.stem());
  const std::vector<fs::path> paths = triplet_files(scan, sidecar_json, settings);
  std::vector<std::pair<fs::path, std::string>> files;
  std::size_t next = 0;
  const auto add_image = [&](const cv::Mat& image) {
    const fs::path& path = paths[next++];
    files.emplace_back(path, encode_image(path, image));
  };
  add_image(range);
  if (scan.has_intensity()) add_image(encode_intensity(scan));
  if (scan.has_color()) add_image(encode_color(scan));
  // Names and paths that are not UTF-8 are written with U+FFFD in their place.
  files.emplace_back(sidecar_json,
                     make_sidecar(scan, stem, settings)
                             .dump(2, ' ', false, nlohmann::json::error_handler_t::replace) +
                         "\n");
  // The sidecar last: a failure leaves the old triplet (or nothing) behind.
  write_files_together(files);
}

std::vector<std::filesystem::path> triplet_files(const Scan& scan,
                                                 const std::filesystem::path& sidecar_json,
                                                 const TripletWriteSettings& settings) {
  const std::string stem = utf8(sidecar_json.stem());
  const fs::path folder = sidecar_json.parent_path();
  const bool float32 = settings.range_encoding == Encoding::kFloat32;
  std::vector<fs::path> paths{folder / from_utf8(stem + (float32 ? "_range.tiff" : "_range.png"))};
  if (scan.has_intensity()) paths.push_back(folder / from_utf8(stem + "_intensity.png"));
  if (scan.has_color()) paths.push_back(folder / from_utf8(stem + "_color.png"));
  paths.push_back(sidecar_json);
  return paths;
}

}  // namespace scanbench::acquisition
