#include "acquisition/formats/image_file.hpp"

#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "acquisition/formats/output_file.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {

std::string encode_image(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  bool ok = false;
  try {
    ok = cv::imencode(path.extension().string(), image, bytes);
  } catch (const cv::Exception& e) {
    throw core::RuntimeFailure(path.string(), {},
                               std::string("could not encode image (") + e.what() + ")");
  }
  if (!ok) throw core::RuntimeFailure(path.string(), {}, "could not encode image");
  return std::string(bytes.begin(), bytes.end());
}

void write_image_file(const std::filesystem::path& path, const cv::Mat& image) {
  OutputFile output(path);
  output.write(encode_image(path, image));
  output.commit();
}

}  // namespace scanbench::acquisition
