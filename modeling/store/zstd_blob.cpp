#include "modeling/store/zstd_blob.hpp"

#include <zstd.h>

#include <bit>
#include <limits>
#include <memory>
#include <new>

#include "core/errors.hpp"

namespace scanbench::store {

// Blobs are the raw in-memory bytes; a big-endian build would need byte swaps
// here to keep project files portable.
static_assert(std::endian::native == std::endian::little,
              "project blobs are little-endian; add byte swapping for this platform");
static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559);
// Vector3f must be three packed floats for the byte view below to be the
// documented x, y, z layout.
static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));

namespace {

[[noreturn]] void throw_bad_blob(const BlobContext& context, const std::string& problem) {
  core::FilePosition position;
  position.detail = context.location;
  throw core::InputError(context.file, position, "damaged channel data: " + problem);
}

// Checked before allocating, so that a damaged size field cannot make us
// reserve gigabytes for a blob that could never fill them.
void check_recorded_size(std::span<const std::uint8_t> blob, std::size_t expected_bytes,
                         const BlobContext& context) {
  const unsigned long long recorded = ZSTD_getFrameContentSize(blob.data(), blob.size());
  if (recorded == ZSTD_CONTENTSIZE_ERROR) throw_bad_blob(context, "not a zstd frame");
  if (recorded == ZSTD_CONTENTSIZE_UNKNOWN) {
    throw_bad_blob(context, "zstd frame does not record its size");
  }
  if (recorded != expected_bytes) {
    throw_bad_blob(context, "holds " + std::to_string(recorded) + " bytes, expected " +
                                std::to_string(expected_bytes));
  }
}

template <typename T>
std::vector<T> decompress_typed(std::span<const std::uint8_t> blob, std::size_t count,
                                const BlobContext& context) {
  if (count > std::numeric_limits<std::size_t>::max() / sizeof(T)) {
    throw_bad_blob(context, "element count " + std::to_string(count) + " is impossible");
  }
  check_recorded_size(blob, count * sizeof(T), context);
  std::vector<T> values(count);
  decompress_into(blob, std::as_writable_bytes(std::span<T>(values)), context);
  return values;
}

}  // namespace

void check_blob_size(std::span<const std::uint8_t> blob, std::size_t expected_bytes,
                     const BlobContext& context) {
  check_recorded_size(blob, expected_bytes, context);
}

std::vector<std::uint8_t> compress(std::span<const std::byte> raw, int level) {
  // A context a thread, kept: creating one allocates and clears zstd's
  // tables, which costs more than compressing a small blob.
  thread_local const std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> context(ZSTD_createCCtx(),
                                                                                  &ZSTD_freeCCtx);
  if (!context) throw std::bad_alloc();
  ZSTD_CCtx_reset(context.get(), ZSTD_reset_session_and_parameters);
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, level);
  // SQLite does not checksum its pages; the frame checksum (4 bytes) lets a
  // damaged blob be reported instead of loading as silently wrong ranges.
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_checksumFlag, 1);
  std::vector<std::uint8_t> blob(ZSTD_compressBound(raw.size()));
  const std::size_t written =
      ZSTD_compress2(context.get(), blob.data(), blob.size(), raw.data(), raw.size());
  // With a ZSTD_compressBound-sized destination the only failure left is
  // running out of memory for zstd's tables.
  if (ZSTD_isError(written)) throw std::bad_alloc();
  blob.resize(written);
  blob.shrink_to_fit();
  return blob;
}

void decompress_into(std::span<const std::uint8_t> blob, std::span<std::byte> out,
                     const BlobContext& context) {
  check_recorded_size(blob, out.size(), context);
  thread_local const std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> zstd(ZSTD_createDCtx(),
                                                                               &ZSTD_freeDCtx);
  if (!zstd) throw std::bad_alloc();
  const std::size_t produced =
      ZSTD_decompressDCtx(zstd.get(), out.data(), out.size(), blob.data(), blob.size());
  if (ZSTD_isError(produced)) throw_bad_blob(context, ZSTD_getErrorName(produced));
  if (produced != out.size()) {
    throw_bad_blob(context, "decoded " + std::to_string(produced) + " bytes, expected " +
                                std::to_string(out.size()));
  }
}

std::vector<std::byte> decompress(std::span<const std::uint8_t> blob, std::size_t expected_bytes,
                                  const BlobContext& context) {
  return decompress_typed<std::byte>(blob, expected_bytes, context);
}

std::vector<std::uint8_t> compress_floats(std::span<const float> values, int level) {
  return compress(std::as_bytes(values), level);
}

std::vector<float> decompress_floats(std::span<const std::uint8_t> blob, std::size_t count,
                                     const BlobContext& context) {
  return decompress_typed<float>(blob, count, context);
}

std::vector<std::uint8_t> compress_bytes(std::span<const std::uint8_t> values, int level) {
  return compress(std::as_bytes(values), level);
}

std::vector<std::uint8_t> decompress_bytes(std::span<const std::uint8_t> blob, std::size_t count,
                                           const BlobContext& context) {
  return decompress_typed<std::uint8_t>(blob, count, context);
}

std::vector<std::uint8_t> compress_vectors(std::span<const Eigen::Vector3f> values, int level) {
  return compress(std::as_bytes(values), level);
}

std::vector<Eigen::Vector3f> decompress_vectors(std::span<const std::uint8_t> blob,
                                                std::size_t count, const BlobContext& context) {
  return decompress_typed<Eigen::Vector3f>(blob, count, context);
}

}  // namespace scanbench::store
