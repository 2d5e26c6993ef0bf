// Compression of scan channel arrays for the project file.
//
// A blob is one zstd frame whose header records the decompressed size and
// which ends in a content checksum, so damage is detected on reading. The
// raw bytes are the array's in-memory representation, which on the supported
// platforms is little-endian IEEE-754 (static_assert in zstd_blob.cpp), so a
// project file written on one machine reads bit for bit on another.
// Eigen::Vector3f arrays are stored as x, y, z floats per element.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace scanbench::store {

// Where a blob came from, so that a decoding failure names it: `file` is the
// project file, `location` e.g. "scan 3, channel range_m".
struct BlobContext {
  std::string file;
  std::string location;
};

// zstd compression level used for channels: fast to write, about 2-4x smaller
// than raw floats on real scans.
inline constexpr int kDefaultCompressionLevel = 3;

// One zstd frame holding `raw`, with the content size in its header and a
// content checksum at its end. `level`
// is a zstd level (1..19; out-of-range values are clamped by zstd). Throws
// std::bad_alloc when zstd cannot allocate its working memory.
std::vector<std::uint8_t> compress(std::span<const std::byte> raw,
                                   int level = kDefaultCompressionLevel);

// Decodes `blob` into `out`, which must have exactly the expected decompressed
// size. Throws core::InputError naming `context` when the blob is not a
// single zstd frame, its recorded size differs from out.size(), or it is
// truncated or damaged; `out` is then unspecified.
void decompress_into(std::span<const std::uint8_t> blob, std::span<std::byte> out,
                     const BlobContext& context);

// Throws core::InputError naming `context` unless `blob` is one zstd frame
// that records exactly `expected_bytes` of content: checked before any
// buffer for it is allocated.
void check_blob_size(std::span<const std::uint8_t> blob, std::size_t expected_bytes,
                     const BlobContext& context);

// As decompress_into, returning a new buffer of `expected_bytes` bytes.
std::vector<std::byte> decompress(std::span<const std::uint8_t> blob, std::size_t expected_bytes,
                                  const BlobContext& context);

// Typed helpers: `count` is the number of elements (not bytes) the blob must
// hold; errors as decompress_into.
std::vector<std::uint8_t> compress_floats(std::span<const float> values,
                                          int level = kDefaultCompressionLevel);
std::vector<float> decompress_floats(std::span<const std::uint8_t> blob, std::size_t count,
                                     const BlobContext& context);

std::vector<std::uint8_t> compress_bytes(std::span<const std::uint8_t> values,
                                         int level = kDefaultCompressionLevel);
std::vector<std::uint8_t> decompress_bytes(std::span<const std::uint8_t> blob, std::size_t count,
                                           const BlobContext& context);

std::vector<std::uint8_t> compress_vectors(std::span<const Eigen::Vector3f> values,
                                           int level = kDefaultCompressionLevel);
std::vector<Eigen::Vector3f> decompress_vectors(std::span<const std::uint8_t> blob,
                                                std::size_t count, const BlobContext& context);

}  // namespace scanbench::store
