// Checksums of the project's records (a scan's metadata, a pose, a journal
// entry). SQLite checksums none of its pages, so a flipped byte in a pose
// would otherwise load as a silently wrong pose; the per-pixel layers carry
// zstd's content checksum instead. Internal to modeling/.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace scanbench::store {

// CRC-32 (zlib's) over a record's fields in a fixed order, each fed with
// its type and length so that no two records share a byte stream.
class RowChecksum {
 public:
  RowChecksum& add(std::int64_t value);
  RowChecksum& add(double value);  // its bits: -0.0 and 0.0 differ
  RowChecksum& add(const std::optional<double>& value);
  RowChecksum& add(std::string_view text);
  RowChecksum& add(std::span<const std::uint8_t> bytes);

  std::int64_t value() const { return static_cast<std::int64_t>(crc_); }

 private:
  void feed(char tag, const void* data, std::size_t size);
  std::uint32_t crc_ = 0;
};

// CRC-32 of a byte range, for content digests.
std::uint32_t crc32_of(std::span<const std::byte> bytes, std::uint32_t crc = 0);

}  // namespace scanbench::store
