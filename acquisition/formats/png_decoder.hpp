// PNG decoding through libpng with our own error handlers: libpng's default
// ones print "libpng error: …" on stderr before our message does, and its
// reason is lost. Here the reason becomes part of the one-line error.
// Internal to decode_image.
#pragma once

#include <filesystem>

#include "acquisition/formats/image_decoder.hpp"

namespace scanbench::acquisition {

// Decodes the PNG at `path`, which must be rows × columns (checked before
// any pixel memory is allocated). Palette and low-bit-depth images are
// expanded to 8 bits, 16-bit samples come out in native byte order, colour
// in OpenCV's BGR order.
DecodedImage decode_png(const std::filesystem::path& path, int rows, int columns);

}  // namespace scanbench::acquisition
