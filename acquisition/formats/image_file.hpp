// Images written as files: encoded in memory by the format the file name's
// extension names (PNG, TIFF), then written all or nothing.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

namespace scanbench::acquisition {

// The bytes of `image` as a file named `path` would hold them. Throws
// core::RuntimeFailure naming `path` when the encoder refuses the image.
std::string encode_image(const std::filesystem::path& path, const cv::Mat& image);

// encode_image, then an OutputFile: the old file stays until the new one is
// complete. Throws as both.
void write_image_file(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace scanbench::acquisition
