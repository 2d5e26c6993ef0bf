#include "acquisition/formats/picture_file.hpp"

#include <cassert>
#include <opencv2/core.hpp>

#include "acquisition/formats/image_file.hpp"

namespace scanbench::acquisition {

void write_rgb_picture(const std::filesystem::path& path, int width, int height,
                       std::span<const std::uint8_t> rgb) {
  assert(rgb.size() == 3 * static_cast<std::size_t>(width) * height);
  cv::Mat bgr(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(rgb[i + 2], rgb[i + 1], rgb[i]);
    }
  }
  write_image_file(path, bgr);
}

}  // namespace scanbench::acquisition
