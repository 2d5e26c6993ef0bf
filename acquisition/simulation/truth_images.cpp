#include "acquisition/simulation/truth_images.hpp"

#include <cassert>
#include <opencv2/core.hpp>
#include <string>
#include <system_error>

#include "acquisition/formats/image_decoder.hpp"
#include "acquisition/formats/image_file.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition::sim {
namespace {

cv::Mat read_image(const std::filesystem::path& path, int type, int rows, int columns) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw core::InputError(path.string(), {}, "missing or unreadable truth image");
  }
  DecodedImage image = decode_image(path, rows, columns);
  if (image.pixels.empty()) throw core::InputError(path.string(), {}, "truth " + image.problem);
  if (image.pixels.type() != type) {
    throw core::InputError(path.string(), {},
                           "truth image has the wrong type (OpenCV type " +
                               std::to_string(image.pixels.type()) + ", expected " +
                               std::to_string(type) + ")");
  }
  return image.pixels;
}

}  // namespace

void write_truth_images(const ScanTruth& truth, int rows, int columns, const TruthFiles& files) {
  [[maybe_unused]] const std::size_t n = static_cast<std::size_t>(rows) * columns;
  assert(truth.object_id.size() == n && truth.normal_scan.size() == n &&
         truth.range_m.size() == n && truth.mixed.size() == n);
  cv::Mat ids(rows, columns, CV_16UC1), normals(rows, columns, CV_32FC3);
  cv::Mat range(rows, columns, CV_32FC1), mixed(rows, columns, CV_8UC1);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < columns; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * columns + col;
      ids.at<std::uint16_t>(row, col) = truth.object_id[i];
      const Eigen::Vector3f& normal = truth.normal_scan[i];
      normals.at<cv::Vec3f>(row, col) = cv::Vec3f(normal.x(), normal.y(), normal.z());
      range.at<float>(row, col) = truth.range_m[i];
      mixed.at<std::uint8_t>(row, col) = truth.mixed[i] ? 255 : 0;
    }
  }
  write_image_file(files.object_id, ids);
  write_image_file(files.normal, normals);
  write_image_file(files.range, range);
  write_image_file(files.mixed, mixed);
}

ScanTruth read_truth_images(const TruthFiles& files, int rows, int columns) {
  const cv::Mat ids = read_image(files.object_id, CV_16UC1, rows, columns);
  const cv::Mat normals = read_image(files.normal, CV_32FC3, rows, columns);
  const cv::Mat range = read_image(files.range, CV_32FC1, rows, columns);
  const cv::Mat mixed = read_image(files.mixed, CV_8UC1, rows, columns);
  ScanTruth truth;
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < columns; ++col) {
      truth.object_id.push_back(ids.at<std::uint16_t>(row, col));
      const cv::Vec3f n = normals.at<cv::Vec3f>(row, col);
      truth.normal_scan.emplace_back(n[0], n[1], n[2]);
      truth.range_m.push_back(range.at<float>(row, col));
      truth.mixed.push_back(mixed.at<std::uint8_t>(row, col) != 0);
    }
  }
  return truth;
}

}  // namespace scanbench::acquisition::sim
