#include "acquisition/formats/png_decoder.hpp"

#include <png.h>

#include <cstdio>
#include <memory>
#include <vector>

namespace scanbench::acquisition {
namespace {

// What libpng reported: its error (it then jumps back to the setjmp) or its
// first warning.
struct Report {
  char error[256] = {};
};

void on_error(png_structp png, png_const_charp message) {
  auto* report = static_cast<Report*>(png_get_error_ptr(png));
  std::snprintf(report->error, sizeof report->error, "%s", message);
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // warnings do not stop decoding; not shown

struct Header {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int depth = 0;     // bits per sample after the transforms
  int channels = 0;  // after the transforms
};

// Reads the header and sets the transforms. Only plain data lives in this
// frame: libpng's longjmp skips no destructor. False after a libpng error.
bool read_header(png_structp png, png_infop info, Header& header) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  const int color_type = png_get_color_type(png, info);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color_type == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8) {
    png_set_expand_gray_1_2_4_to_8(png);
  }
  if (png_get_bit_depth(png, info) == 16) png_set_swap(png);  // PNG is big-endian
  if (color_type & PNG_COLOR_MASK_COLOR) png_set_bgr(png);    // OpenCV's channel order
  png_read_update_info(png, info);
  header.width = png_get_image_width(png, info);
  header.height = png_get_image_height(png, info);
  header.depth = png_get_bit_depth(png, info);
  header.channels = png_get_channels(png, info);
  return true;
}

// Reads every row into `rows` (allocated by the caller). False after an error.
bool read_rows(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, info);
  return true;
}

}  // namespace

DecodedImage decode_png(const std::filesystem::path& path, int rows, int columns) {
  DecodedImage result;
  const std::unique_ptr<std::FILE, decltype(&std::fclose)> file(std::fopen(path.c_str(), "rb"),
                                                                &std::fclose);
  if (!file) return {{}, "cannot open the file"};
  Report report;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &report, on_error, on_warning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  const auto destroy = [&] { png_destroy_read_struct(&png, &info, nullptr); };
  if (png == nullptr || info == nullptr) {
    destroy();
    return {{}, "out of memory for the PNG decoder"};
  }
  png_init_io(png, file.get());
  Header header;
  if (!read_header(png, info, header)) {
    destroy();
    return {{}, unreadable(std::string("libpng: ") + report.error)};
  }
  if (header.height != static_cast<png_uint_32>(rows) ||
      header.width != static_cast<png_uint_32>(columns)) {
    destroy();
    return {{}, size_differs(header.height, header.width, rows, columns)};
  }
  result.pixels.create(rows, columns,
                       CV_MAKETYPE(header.depth == 16 ? CV_16U : CV_8U, header.channels));
  std::vector<png_bytep> row_pointers(static_cast<std::size_t>(rows));
  for (int row = 0; row < rows; ++row)
    row_pointers[static_cast<std::size_t>(row)] = result.pixels.ptr(row);
  const bool read = read_rows(png, info, row_pointers.data());
  destroy();
  if (!read) return {{}, unreadable(std::string("libpng: ") + report.error)};
  return result;
}

}  // namespace scanbench::acquisition
