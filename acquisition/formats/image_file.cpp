// Our own PNG and TIFF encoders on libpng and libtiff, in memory. They
// replace OpenCV's imgcodecs, whose GDAL, DICOM and video dependencies
// cost every scanbench command a tenth of a second of dynamic linking
// before main() runs.
#include "acquisition/formats/image_file.hpp"

#include <png.h>
#include <tiffio.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <new>

#include "acquisition/formats/image_decoder.hpp"
#include "acquisition/formats/output_file.hpp"
#include "core/errors.hpp"
#include "core/text.hpp"

namespace scanbench::acquisition {
namespace {

std::string lower_extension(const std::filesystem::path& path) {
  return core::ascii_lower(path.extension().string());
}

// ---- PNG -------------------------------------------------------------

struct PngOutput {
  std::string bytes;
  std::string problem;
};

// No exception may cross libpng's C frames: running out of memory becomes
// a libpng error.
void on_png_write(png_structp png, png_bytep data, png_size_t size) {
  bool stored = true;
  try {
    static_cast<PngOutput*>(png_get_io_ptr(png))->bytes.append(reinterpret_cast<char*>(data), size);
  } catch (const std::bad_alloc&) {
    stored = false;
  }
  if (!stored) png_error(png, "out of memory");
}
void on_png_flush(png_structp) {}
void on_png_error(png_structp png, png_const_charp message) {
  static_cast<PngOutput*>(png_get_error_ptr(png))->problem = message;
  png_longjmp(png, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

// Every row of `image` (8 or 16-bit, 1, 3 or 4 channels in B, G, R(, A)
// order) into `output`. False, with output.problem set, when libpng fails.
// Plain data only between setjmp and the calls that may jump back.
bool write_png(const cv::Mat& image, PngOutput& output) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &output, on_png_error, on_png_warning);
  if (png == nullptr) {
    output.problem = "libpng could not start";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    if (output.problem.empty()) output.problem = "libpng could not start";
    return false;
  }
  static constexpr int kColorTypes[5] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                         PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
  png_set_write_fn(png, &output, on_png_write, on_png_flush);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows), image.depth() == CV_16U ? 16 : 8,
               kColorTypes[image.channels()], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  // Fast deflate: exports of millions of pixels should not wait on zlib.
  png_set_compression_level(png, 1);
  png_write_info(png, info);
  if (image.depth() == CV_16U) png_set_swap(png);  // PNG is big-endian
  if (image.channels() >= 3) png_set_bgr(png);
  for (int row = 0; row < image.rows; ++row) {
    png_write_row(png, image.ptr<png_byte>(row));
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

// ---- TIFF ------------------------------------------------------------

// A growing file in memory for libtiff, which seeks back to patch offsets.
struct TiffMemory {
  std::string bytes;
  toff_t position = 0;
  std::string problem;
};

tmsize_t on_tiff_read(thandle_t handle, void* data, tmsize_t size) {
  auto* file = static_cast<TiffMemory*>(handle);
  if (file->position >= file->bytes.size()) return 0;
  const auto n = std::min<toff_t>(static_cast<toff_t>(size), file->bytes.size() - file->position);
  std::memcpy(data, file->bytes.data() + file->position, n);
  file->position += n;
  return static_cast<tmsize_t>(n);
}
tmsize_t on_tiff_write(thandle_t handle, void* data, tmsize_t size) {
  auto* file = static_cast<TiffMemory*>(handle);
  const auto end = file->position + static_cast<toff_t>(size);
  try {
    if (end > file->bytes.size()) file->bytes.resize(end);
  } catch (const std::bad_alloc&) {
    file->problem = "out of memory";
    return -1;  // libtiff fails the write; no exception crosses its C frames
  }
  std::memcpy(file->bytes.data() + file->position, data, static_cast<std::size_t>(size));
  file->position = end;
  return size;
}
toff_t on_tiff_seek(thandle_t handle, toff_t offset, int whence) {
  auto* file = static_cast<TiffMemory*>(handle);
  const toff_t base = whence == SEEK_CUR   ? file->position
                      : whence == SEEK_END ? file->bytes.size()
                                           : 0;
  file->position = base + offset;
  return file->position;
}
int on_tiff_close(thandle_t) {
  return 0;
}
toff_t on_tiff_size(thandle_t handle) {
  return static_cast<TiffMemory*>(handle)->bytes.size();
}
int on_tiff_error(TIFF*, void* user_data, const char* module, const char* format, va_list args) {
  auto* file = static_cast<TiffMemory*>(user_data);
  if (!file->problem.empty()) return 1;
  char text[256];
  std::vsnprintf(text, sizeof text, format, args);
  file->problem = std::string("libtiff: ") + (module != nullptr ? module : "") + ": " + text;
  return 1;
}
int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) {
  return 1;
}

// `image` (8 or 16-bit unsigned or 32-bit float, 1, 3 or 4 channels in
// B, G, R(, A) order) as one deflated TIFF with a predictor, in strips.
bool write_tiff(const cv::Mat& image, TiffMemory& file) {
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  TIFFOpenOptionsSetErrorHandlerExtR(options, on_tiff_error, &file);
  TIFFOpenOptionsSetWarningHandlerExtR(options, on_tiff_warning, nullptr);
  using TiffHandle = std::unique_ptr<TIFF, decltype(&TIFFClose)>;
  TiffHandle tiff(TIFFClientOpenExt("memory", "w", &file, on_tiff_read, on_tiff_write, on_tiff_seek,
                                    on_tiff_close, on_tiff_size, nullptr, nullptr, options),
                  &TIFFClose);
  TIFFOpenOptionsFree(options);
  if (!tiff) return false;
  const bool floats = image.depth() == CV_32F;
  const auto samples = static_cast<std::uint16_t>(image.channels());
  TIFF* t = tiff.get();
  TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(image.cols));
  TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(image.rows));
  TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, static_cast<std::uint16_t>(8 * image.elemSize1()));
  TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, samples);
  TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, floats ? SAMPLEFORMAT_IEEEFP : SAMPLEFORMAT_UINT);
  TIFFSetField(t, TIFFTAG_PHOTOMETRIC, samples >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  if (samples == 4 || samples == 2) {
    const std::uint16_t extra = EXTRASAMPLE_UNASSALPHA;
    TIFFSetField(t, TIFFTAG_EXTRASAMPLES, 1, &extra);
  }
  TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
  TIFFSetField(t, TIFFTAG_ZIPQUALITY, 1);
  TIFFSetField(t, TIFFTAG_PREDICTOR, floats ? PREDICTOR_FLOATINGPOINT : PREDICTOR_HORIZONTAL);
  TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(t, 0));
  const cv::Mat rgb = swap_red_blue(image);
  std::vector<std::uint8_t> row_bytes(rgb.cols * rgb.elemSize());  // libtiff may scribble on it
  for (int row = 0; row < rgb.rows; ++row) {
    std::memcpy(row_bytes.data(), rgb.ptr(row), row_bytes.size());
    if (TIFFWriteScanline(t, row_bytes.data(), static_cast<std::uint32_t>(row), 0) < 0) {
      return false;
    }
  }
  return TIFFWriteDirectory(t) == 1;
}

}  // namespace

std::string encode_image(const std::filesystem::path& path, const cv::Mat& image) {
  const std::string extension = lower_extension(path);
  const bool png = extension == ".png";
  const bool tiff = extension == ".tif" || extension == ".tiff";
  if (!png && !tiff) {
    throw core::RuntimeFailure(path.string(), {},
                               "images are written as .png or .tiff, not '" + extension + "'");
  }
  const int depth = image.depth();
  const bool supported = image.channels() >= 1 && image.channels() <= 4 && !image.empty() &&
                         (depth == CV_8U || depth == CV_16U || (tiff && depth == CV_32F));
  if (!supported) {
    throw core::RuntimeFailure(path.string(), {},
                               "could not encode image (" + std::to_string(image.channels()) +
                                   " channels of OpenCV depth " + std::to_string(depth) + ")");
  }
  const cv::Mat pixels = image.isContinuous() ? image : image.clone();
  if (png) {
    PngOutput output;
    if (!write_png(pixels, output)) {
      throw core::RuntimeFailure(path.string(), {},
                                 "could not encode image (libpng: " + output.problem + ")");
    }
    return std::move(output.bytes);
  }
  TiffMemory file;
  if (!write_tiff(pixels, file)) {
    throw core::RuntimeFailure(
        path.string(), {},
        "could not encode image (" +
            (file.problem.empty() ? std::string("libtiff failed") : file.problem) + ")");
  }
  return std::move(file.bytes);
}

void write_image_file(const std::filesystem::path& path, const cv::Mat& image) {
  OutputFile output(path);
  output.write(encode_image(path, image));
  output.commit();
}

}  // namespace scanbench::acquisition
