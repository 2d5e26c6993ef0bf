#include "modeling/store/row_checksum.hpp"

#include <zlib.h>

#include <cstring>
#include <limits>

namespace scanbench::store {

std::uint32_t crc32_of(std::span<const std::byte> bytes, std::uint32_t crc) {
  // zlib takes at most 4 GB at a time.
  const auto* data = reinterpret_cast<const Bytef*>(bytes.data());
  std::size_t left = bytes.size();
  uLong value = crc;
  while (left > 0) {
    const auto chunk = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
    value = ::crc32(value, data, chunk);
    data += chunk;
    left -= chunk;
  }
  return static_cast<std::uint32_t>(value);
}

void RowChecksum::feed(char tag, const void* data, std::size_t size) {
  const std::uint64_t length = size;
  crc_ = crc32_of(std::as_bytes(std::span(&tag, 1)), crc_);
  crc_ = crc32_of(std::as_bytes(std::span(&length, 1)), crc_);
  crc_ = crc32_of(std::span(static_cast<const std::byte*>(data), size), crc_);
}

RowChecksum& RowChecksum::add(std::int64_t value) {
  feed('i', &value, sizeof value);
  return *this;
}

RowChecksum& RowChecksum::add(double value) {
  feed('d', &value, sizeof value);
  return *this;
}

RowChecksum& RowChecksum::add(const std::optional<double>& value) {
  if (!value) {
    feed('n', nullptr, 0);
    return *this;
  }
  return add(*value);
}

RowChecksum& RowChecksum::add(std::string_view text) {
  feed('s', text.data(), text.size());
  return *this;
}

RowChecksum& RowChecksum::add(std::span<const std::uint8_t> bytes) {
  feed('b', bytes.data(), bytes.size());
  return *this;
}

}  // namespace scanbench::store
