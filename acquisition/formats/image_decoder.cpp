#include "acquisition/formats/image_decoder.hpp"

#include <tiffio.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <vector>

#include "acquisition/formats/png_decoder.hpp"

namespace scanbench::acquisition {
namespace {

enum class Format { kPng, kTiff, kPnm, kOther };

// By the magic bytes: the PNG signature, "II*\0" / "MM\0*", "P1"…"P6",
// "PF" / "Pf".
Format format_of(const std::filesystem::path& path) {
  std::array<unsigned char, 8> head{};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(head.data()), head.size());
  const auto got = in.gcount();
  static constexpr unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (got == 8 && std::memcmp(head.data(), kPng, 8) == 0) return Format::kPng;
  if (got >= 4 && ((head[0] == 'I' && head[1] == 'I' && head[2] == 42 && head[3] == 0) ||
                   (head[0] == 'M' && head[1] == 'M' && head[2] == 0 && head[3] == 42))) {
    return Format::kTiff;
  }
  if (got >= 2 && head[0] == 'P' &&
      ((head[1] >= '1' && head[1] <= '6') || head[1] == 'F' || head[1] == 'f')) {
    return Format::kPnm;
  }
  return Format::kOther;
}

// ---- TIFF ------------------------------------------------------------

// The first error libtiff reports while a file is open, as text.
int on_tiff_error(TIFF*, void* user_data, const char* module, const char* format, va_list args) {
  auto* problem = static_cast<std::string*>(user_data);
  if (!problem->empty()) return 1;
  char text[256];
  std::vsnprintf(text, sizeof text, format, args);
  *problem = std::string("libtiff: ") + (module != nullptr ? module : "") + ": " + text;
  return 1;  // handled: libtiff prints nothing
}

int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) {
  return 1;  // warnings do not stop reading; not shown
}

using TiffHandle = std::unique_ptr<TIFF, decltype(&TIFFClose)>;

TiffHandle open_tiff(const std::filesystem::path& path, std::string& problem,
                     std::size_t max_allocation) {
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  TIFFOpenOptionsSetErrorHandlerExtR(options, on_tiff_error, &problem);
  TIFFOpenOptionsSetWarningHandlerExtR(options, on_tiff_warning, nullptr);
  // No single allocation beyond what a strip of this image can need: a
  // strip byte count a header makes up cannot cost gigabytes.
  TIFFOpenOptionsSetMaxSingleMemAlloc(options, static_cast<tmsize_t>(max_allocation));
  TiffHandle tiff(TIFFOpenExt(path.c_str(), "r", options), &TIFFClose);
  TIFFOpenOptionsFree(options);
  return tiff;
}

struct TiffLayout {
  std::uint16_t bits = 1;
  std::uint16_t samples = 1;
  std::uint16_t sample_format = SAMPLEFORMAT_UINT;
  std::uint16_t planar = PLANARCONFIG_CONTIG;
  std::uint16_t photometric = PHOTOMETRIC_MINISBLACK;
};

// The OpenCV depth of the layout, or -1 with `problem` set.
int tiff_depth(const TiffLayout& t, std::string& problem) {
  int depth = -1;
  if (t.sample_format == SAMPLEFORMAT_UINT && t.bits == 8) depth = CV_8U;
  if (t.sample_format == SAMPLEFORMAT_UINT && t.bits == 16) depth = CV_16U;
  if (t.sample_format == SAMPLEFORMAT_IEEEFP && t.bits == 32) depth = CV_32F;
  const bool gray = t.samples == 1 && t.photometric == PHOTOMETRIC_MINISBLACK;
  const bool rgb = (t.samples == 3 || t.samples == 4) && t.photometric == PHOTOMETRIC_RGB;
  if (depth >= 0 && (gray || rgb) && t.planar == PLANARCONFIG_CONTIG) return depth;
  static const char* const kFormats[] = {"",     "unsigned",    "signed",       "float",
                                         "void", "complex int", "complex float"};
  const char* format = t.sample_format < 7 ? kFormats[t.sample_format] : "unknown";
  problem = "wrong image type: a TIFF of " + std::to_string(t.bits) + "-bit " + format +
            " samples, " + std::to_string(t.samples) + " per pixel, photometric " +
            std::to_string(t.photometric) +
            (t.planar == PLANARCONFIG_CONTIG ? "" : ", in separate planes") +
            "; grey or RGB(A) with 8 or 16-bit unsigned or 32-bit float samples, interleaved, are "
            "read";
  return -1;
}

bool read_tiff_strips(TIFF* tiff, cv::Mat& pixels) {
  if (TIFFScanlineSize64(tiff) != pixels.cols * pixels.elemSize()) return false;
  for (int row = 0; row < pixels.rows; ++row) {
    if (TIFFReadScanline(tiff, pixels.ptr(row), static_cast<std::uint32_t>(row), 0) < 0)
      return false;
  }
  return true;
}

bool read_tiff_tiles(TIFF* tiff, cv::Mat& pixels) {
  std::uint32_t tile_width = 0, tile_length = 0;
  if (TIFFGetField(tiff, TIFFTAG_TILEWIDTH, &tile_width) != 1 ||
      TIFFGetField(tiff, TIFFTAG_TILELENGTH, &tile_length) != 1 || tile_width == 0 ||
      tile_length == 0) {
    return false;
  }
  // Tiles are multiples of 16 wide and long, so never much beyond the image.
  if (tile_width > static_cast<std::uint32_t>(pixels.cols) + 16 ||
      tile_length > static_cast<std::uint32_t>(pixels.rows) + 16) {
    return false;
  }
  const std::size_t pixel_bytes = pixels.elemSize();
  if (TIFFTileSize64(tiff) != std::uint64_t{tile_width} * tile_length * pixel_bytes) return false;
  std::vector<std::uint8_t> tile(static_cast<std::size_t>(TIFFTileSize64(tiff)));
  const auto rows = static_cast<std::uint32_t>(pixels.rows);
  const auto cols = static_cast<std::uint32_t>(pixels.cols);
  for (std::uint32_t y = 0; y < rows; y += tile_length) {
    for (std::uint32_t x = 0; x < cols; x += tile_width) {
      if (TIFFReadTile(tiff, tile.data(), x, y, 0, 0) < 0) return false;
      const std::uint32_t copy_rows = std::min(tile_length, rows - y);
      const std::size_t copy_bytes = std::min(tile_width, cols - x) * pixel_bytes;
      for (std::uint32_t r = 0; r < copy_rows; ++r) {
        std::memcpy(pixels.ptr(static_cast<int>(y + r)) + x * pixel_bytes,
                    tile.data() + r * tile_width * pixel_bytes, copy_bytes);
      }
    }
  }
  return true;
}

DecodedImage decode_tiff(const std::filesystem::path& path, int rows, int columns) {
  std::string problem;
  // Generous: a strip of the whole image in 4 float channels, or 64 MB.
  const std::size_t max_allocation =
      std::max<std::size_t>(std::size_t{64} << 20, static_cast<std::size_t>(rows) * columns * 16);
  const TiffHandle tiff = open_tiff(path, problem, max_allocation);
  if (!tiff) return {{}, unreadable(problem.empty() ? "not a readable TIFF" : problem)};
  std::uint32_t width = 0, height = 0;
  if (TIFFGetField(tiff.get(), TIFFTAG_IMAGEWIDTH, &width) != 1 ||
      TIFFGetField(tiff.get(), TIFFTAG_IMAGELENGTH, &height) != 1) {
    return {{}, unreadable("the TIFF declares no size")};
  }
  if (height != static_cast<std::uint32_t>(rows) || width != static_cast<std::uint32_t>(columns))
    return {{}, size_differs(height, width, rows, columns)};
  TiffLayout layout;
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_BITSPERSAMPLE, &layout.bits);
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_SAMPLESPERPIXEL, &layout.samples);
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_SAMPLEFORMAT, &layout.sample_format);
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_PLANARCONFIG, &layout.planar);
  if (TIFFGetField(tiff.get(), TIFFTAG_PHOTOMETRIC, &layout.photometric) != 1) {
    // Writers that leave it out mean the obvious.
    layout.photometric = layout.samples >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK;
  }
  const int depth = tiff_depth(layout, problem);
  if (depth < 0) return {{}, problem};
  DecodedImage result;
  result.pixels.create(rows, columns, CV_MAKETYPE(depth, layout.samples));
  const bool read = TIFFIsTiled(tiff.get()) != 0 ? read_tiff_tiles(tiff.get(), result.pixels)
                                                 : read_tiff_strips(tiff.get(), result.pixels);
  if (!read)
    return {{}, unreadable(problem.empty() ? "the TIFF's pixel data cannot be read" : problem)};
  result.pixels = swap_red_blue(result.pixels);
  return result;
}

// ---- PNM and PFM -----------------------------------------------------

// Reads a PNM file's header tokens and samples; every failure is a reason.
class PnmReader {
 public:
  explicit PnmReader(const std::filesystem::path& path) : in_(path, std::ios::binary) {}

  // The next header token: blanks and "#" comments before it are skipped.
  bool token(std::string& out) {
    out.clear();
    int c = in_.get();
    while (c != EOF && (std::isspace(c) != 0 || c == '#')) {
      if (c == '#') {
        while (c != EOF && c != '\n') c = in_.get();
      }
      c = in_.get();
    }
    for (; c != EOF && std::isspace(c) == 0 && c != '#' && out.size() < 64; c = in_.get())
      out += static_cast<char>(c);
    // The one blank after the last header token belongs to the header.
    return !out.empty();
  }

  bool number(long long limit, long long& value) {
    std::string text;
    if (!token(text) || text.size() > 18) return false;
    value = 0;
    for (const char c : text) {
      if (std::isdigit(static_cast<unsigned char>(c)) == 0) return false;
      value = value * 10 + (c - '0');
    }
    return value <= limit;
  }

  // Bytes still to come after the header.
  std::uintmax_t remaining(const std::filesystem::path& path) {
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    const std::streamoff at = in_.tellg();
    return error || at < 0 || static_cast<std::uintmax_t>(at) > size
               ? 0
               : size - static_cast<std::uintmax_t>(at);
  }

  bool bytes(void* out, std::size_t count) {
    in_.read(static_cast<char*>(out), static_cast<std::streamsize>(count));
    return static_cast<std::size_t>(in_.gcount()) == count;
  }

 private:
  std::ifstream in_;
};

// Reverses the byte order of every `sample_bytes`-wide sample.
void swap_bytes(cv::Mat& pixels, std::size_t sample_bytes) {
  std::uint8_t* sample = pixels.data;
  const std::uint8_t* const end = pixels.data + pixels.total() * pixels.elemSize();
  for (; sample < end; sample += sample_bytes) std::reverse(sample, sample + sample_bytes);
}

// PFM: "Pf" (grey) or "PF" (RGB), the scale's sign the byte order
// (negative: little-endian), rows from the bottom up.
DecodedImage decode_pfm(PnmReader& in, const std::filesystem::path& path, int channels, int rows,
                        int columns) {
  std::string scale_text;
  if (!in.token(scale_text)) return {{}, unreadable("PFM header without its scale")};
  char* end = nullptr;
  const double scale = std::strtod(scale_text.c_str(), &end);
  if (*end != '\0' || !std::isfinite(scale) || scale == 0.0)
    return {{}, unreadable("PFM scale \"" + scale_text + "\" is not a non-zero number")};
  DecodedImage result;
  result.pixels.create(rows, columns, CV_32FC(channels));
  const std::size_t row_bytes = result.pixels.cols * result.pixels.elemSize();
  if (in.remaining(path) < row_bytes * rows)
    return {{}, unreadable("the PFM file ends before its last sample")};
  for (int row = rows - 1; row >= 0; --row) in.bytes(result.pixels.ptr(row), row_bytes);
  const bool little = scale < 0.0;
  if (little != (std::endian::native == std::endian::little)) swap_bytes(result.pixels, 4);
  result.pixels = swap_red_blue(result.pixels);
  return result;
}

// P2/P3 (text) and P5/P6 (binary) grey and RGB maps, 8-bit when maxval
// is below 256, else 16-bit big-endian. Samples are kept as stored, as
// OpenCV does, not scaled to maxval.
DecodedImage decode_pnm_samples(PnmReader& in, const std::filesystem::path& path, char kind,
                                int rows, int columns) {
  long long maxval = 0;
  if (!in.number(65535, maxval) || maxval == 0)
    return {{}, unreadable("PNM maxval missing or not within 1 to 65535")};
  const int channels = kind == '3' || kind == '6' ? 3 : 1;
  const bool binary = kind == '5' || kind == '6';
  DecodedImage result;
  result.pixels.create(rows, columns, CV_MAKETYPE(maxval < 256 ? CV_8U : CV_16U, channels));
  const std::size_t count = result.pixels.total() * channels;
  const std::size_t sample_bytes = result.pixels.elemSize1();
  if (binary) {
    if (in.remaining(path) < count * sample_bytes)
      return {{}, unreadable("the PNM file ends before its last sample")};
    in.bytes(result.pixels.data, count * sample_bytes);
    if (sample_bytes == 2 && std::endian::native == std::endian::little)
      swap_bytes(result.pixels, 2);
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      long long value = 0;
      if (!in.number(maxval, value)) {
        return {{},
                unreadable("PNM sample " + std::to_string(i + 1) + " of " + std::to_string(count) +
                           " missing or above maxval " + std::to_string(maxval))};
      }
      if (sample_bytes == 1)
        result.pixels.data[i] = static_cast<std::uint8_t>(value);
      else
        reinterpret_cast<std::uint16_t*>(result.pixels.data)[i] = static_cast<std::uint16_t>(value);
    }
  }
  result.pixels = swap_red_blue(result.pixels);
  return result;
}

DecodedImage decode_pnm(const std::filesystem::path& path, int rows, int columns) {
  PnmReader in(path);
  std::string magic;
  in.token(magic);
  const char kind = magic.size() == 2 ? magic[1] : '?';
  if (kind == '1' || kind == '4')
    return {{}, "wrong image type: a 1-bit PBM bitmap; grey, colour or float maps are read"};
  long long width = 0, height = 0;
  if (!in.number(std::numeric_limits<int>::max(), width) ||
      !in.number(std::numeric_limits<int>::max(), height)) {
    return {{}, unreadable("PNM header without a usable width and height")};
  }
  if (height != rows || width != columns) return {{}, size_differs(height, width, rows, columns)};
  if (kind == 'f' || kind == 'F') return decode_pfm(in, path, kind == 'F' ? 3 : 1, rows, columns);
  return decode_pnm_samples(in, path, kind, rows, columns);
}

}  // namespace

std::string size_differs(long long rows, long long columns, int expected_rows,
                         int expected_columns) {
  return "image size " + std::to_string(rows) + " x " + std::to_string(columns) +
         " differs from the sidecar's " + std::to_string(expected_rows) + " x " +
         std::to_string(expected_columns);
}

DecodedImage decode_image(const std::filesystem::path& path, int rows, int columns) {
  switch (format_of(path)) {
    case Format::kPng:
      return decode_png(path, rows, columns);
    case Format::kTiff:
      return decode_tiff(path, rows, columns);
    case Format::kPnm:
      return decode_pnm(path, rows, columns);
    case Format::kOther:
      break;
  }
  std::error_code error;
  return {
      {},
      unreadable(std::filesystem::file_size(path, error) == 0 ? "the file is empty"
                                                              : "not a PNG, TIFF or PNM image")};
}

cv::Mat swap_red_blue(const cv::Mat& pixels) {
  if (pixels.channels() < 3) return pixels;
  cv::Mat swapped(pixels.size(), pixels.type());
  const std::array<int, 8> pairs = {0, 2, 1, 1, 2, 0, 3, 3};
  cv::mixChannels(&pixels, 1, &swapped, 1, pairs.data(),
                  static_cast<std::size_t>(pixels.channels()));
  return swapped;
}

}  // namespace scanbench::acquisition
