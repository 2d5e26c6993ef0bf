// PNG decoding through libpng with our own error handlers: libpng's default
// ones print "libpng error: …" on stderr before our message does, and its
// reason is lost. Here the reason becomes part of the one-line error.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace scanbench::acquisition {

struct PngDecodeResult {
  cv::Mat pixels;  // as cv::imread(IMREAD_UNCHANGED) gives them: 8 or 16 bit, gray or BGR(A)
  // Empty pixels: why (libpng's words, or a size that differs from the expected).
  std::string problem;
};

// Decodes the PNG at `path`, which must be rows × columns (checked before
// any pixel memory is allocated). Palette and low-bit-depth images are
// expanded to 8 bits, 16-bit samples come out in native byte order, colour
// in OpenCV's BGR order. Never throws for bad data; prints nothing.
PngDecodeResult decode_png(const std::filesystem::path& path, int rows, int columns);

}  // namespace scanbench::acquisition
