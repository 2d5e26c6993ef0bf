// The images a triplet names, decoded by our own code on libpng and
// libtiff, with their handlers: nothing is printed on stderr (OpenCV's
// imread prints "can't read header" lines), every reason becomes part of
// one error, and the size a header declares is checked against the
// sidecar's before any pixel memory is allocated (a 200-byte TIFF that
// declares 30000 × 30000 floats gets no 3.6 GB). Internal to
// acquisition: the triplet reader and the simulator's truth images read
// through it.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

namespace scanbench::acquisition {

struct DecodedImage {
  // As cv::imread(IMREAD_UNCHANGED) gives them: 8 or 16-bit unsigned or
  // 32-bit float samples, 1, 3 or 4 channels, colour in B, G, R order.
  cv::Mat pixels;
  // Empty pixels: why, one line (the decoder's words, or a size that
  // differs from the expected).
  std::string problem;
};

// Decodes the image at `path`, which must be rows × columns. The format is
// told by the file's first bytes, never its name: PNG, TIFF (strips or
// tiles, any compression libtiff reads, interleaved samples), and the PNM
// family: P2, P3, P5, P6 (maxval up to 65535) and PFM ("Pf", "PF").
// Never throws for bad data.
DecodedImage decode_image(const std::filesystem::path& path, int rows, int columns);

// The parts that need no file, for decode_image and the PNG decoder.
std::string size_differs(long long rows, long long columns, int expected_rows,
                         int expected_columns);
// The image with its first and third channels exchanged (R, G, B(, A) ⇄
// B, G, R(, A)); one or two channels come back as they are. Files hold RGB,
// OpenCV's images BGR: the decoder and the encoder (image_file.cpp) both
// cross here.
cv::Mat swap_red_blue(const cv::Mat& pixels);
inline std::string unreadable(const std::string& reason) {
  return "image is unreadable or corrupt (" + reason + ")";
}

}  // namespace scanbench::acquisition
