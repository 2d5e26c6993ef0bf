// Pictures from code that does not know OpenCV (the renderer, the CLI):
// plain pixel arrays written through image_file.hpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

namespace scanbench::acquisition {

// An 8-bit RGB picture (row-major, top row first, 3 bytes per pixel) encoded
// by the file name's extension (.png) and written all or nothing, as
// write_image_file does. Asserts rgb.size() == 3 · width · height.
void write_rgb_picture(const std::filesystem::path& path, int width, int height,
                       std::span<const std::uint8_t> rgb);

}  // namespace scanbench::acquisition
