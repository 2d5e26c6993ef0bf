#include "acquisition/formats/e57/e57_bitpack.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstring>

namespace scanbench::acquisition {
namespace {

// Reads the `bits` (1..64) bits at bit position `position` of `data`, which
// holds at least 16 readable bytes from position / 8.
std::uint64_t read_bits(const unsigned char* data, std::uint64_t position, int bits) {
  std::uint64_t low = 0;
  std::uint64_t high = 0;
  std::memcpy(&low, data + position / 8, 8);
  std::memcpy(&high, data + position / 8 + 8, 8);
  const unsigned shift = position % 8;
  std::uint64_t value = shift == 0 ? low : (low >> shift) | (high << (64 - shift));
  return bits == 64 ? value : value & ((std::uint64_t{1} << bits) - 1);
}

bool unpack_integers(const E57Field& field, std::span<const std::byte> stream, std::uint64_t first,
                     std::span<double> out) {
  const int bits = field.bits();
  const std::uint64_t begin_bit = first * static_cast<std::uint64_t>(bits);
  assert(bits <= 64);
  const std::uint64_t end_byte = e57_stream_bytes(field, first + out.size());
  if (stream.size() < end_byte) return false;
  const bool scaled = field.type == E57FieldType::kScaledInteger;
  if (bits == 0) {
    const double value = scaled ? static_cast<double>(field.minimum) * field.scale + field.offset
                                : static_cast<double>(field.minimum);
    std::fill(out.begin(), out.end(), value);
    return true;
  }
  // Records whose two-word read stays inside the stream decode in place;
  // the last few from a copy padded with zeros.
  const auto* data = reinterpret_cast<const unsigned char*>(stream.data());
  const auto minimum = static_cast<std::uint64_t>(field.minimum);
  const auto value_of = [&](std::uint64_t packed) {
    // Wrapping unsigned addition: minimum + packed stays within the int64
    // range (it can exceed maximum when maximum − minimum + 1 is not a power
    // of two; the value is taken as stored).
    const auto raw = static_cast<std::int64_t>(minimum + packed);
    return scaled ? static_cast<double>(raw) * field.scale + field.offset
                  : static_cast<double>(raw);
  };
  std::uint64_t position = begin_bit;
  std::size_t k = 0;
  // The in-place records: up to the last one whose 16-byte read fits.
  const std::uint64_t in_place_bits =
      stream.size() >= 16 ? (stream.size() - 16) * 8 + 1 : 0;  // positions below this
  const std::size_t in_place =
      position >= in_place_bits
          ? 0
          : std::min<std::size_t>(out.size(), (in_place_bits - position + bits - 1) / bits);
  if (bits <= 56) {
    // One 8-byte load holds the record's bits whatever its bit offset.
    const std::uint64_t mask = (std::uint64_t{1} << bits) - 1;
    for (; k < in_place; ++k, position += static_cast<std::uint64_t>(bits)) {
      std::uint64_t word;
      std::memcpy(&word, data + position / 8, 8);
      out[k] = value_of((word >> (position % 8)) & mask);
    }
  }
  for (; k < in_place; ++k, position += static_cast<std::uint64_t>(bits)) {
    out[k] = value_of(read_bits(data, position, bits));
  }
  if (k == out.size()) return true;
  const std::uint64_t tail_byte = position / 8;
  std::array<unsigned char, 48> tail{};  // at most 16 bytes of stream and 16 of padding
  std::memcpy(tail.data(), data + tail_byte, end_byte - tail_byte);
  for (position -= tail_byte * 8; k < out.size(); ++k) {
    out[k] = value_of(read_bits(tail.data(), position, bits));
    position += static_cast<std::uint64_t>(bits);
  }
  return true;
}

template <typename Real>
bool unpack_floats(std::span<const std::byte> stream, std::uint64_t first, std::span<double> out) {
  if (stream.size() < (first + out.size()) * sizeof(Real)) return false;
  const std::byte* data = stream.data() + first * sizeof(Real);
  for (std::size_t i = 0; i < out.size(); ++i) {
    Real value;
    std::memcpy(&value, data + i * sizeof(Real), sizeof(Real));
    out[i] = static_cast<double>(value);
  }
  return true;
}

std::int64_t raw_integer(const E57Field& field, double value) {
  const double raw = field.type == E57FieldType::kScaledInteger
                         ? std::round((value - field.offset) / field.scale)
                         : std::round(value);
  if (!(raw > static_cast<double>(field.minimum))) return field.minimum;
  if (!(raw < static_cast<double>(field.maximum))) return field.maximum;
  return static_cast<std::int64_t>(raw);
}

}  // namespace

int E57Field::bits() const {
  if (type == E57FieldType::kFloat) return single_precision ? 32 : 64;
  assert(maximum >= minimum);
  const std::uint64_t span =
      static_cast<std::uint64_t>(maximum) - static_cast<std::uint64_t>(minimum);
  return span == 0 ? 0 : static_cast<int>(std::bit_width(span));
}

std::uint64_t e57_stream_bytes(const E57Field& field, std::uint64_t records) {
  return (records * static_cast<std::uint64_t>(field.bits()) + 7) / 8;
}

bool e57_unpack(const E57Field& field, std::span<const std::byte> stream, std::uint64_t first,
                std::span<double> out) {
  if (field.type != E57FieldType::kFloat) return unpack_integers(field, stream, first, out);
  return field.single_precision ? unpack_floats<float>(stream, first, out)
                                : unpack_floats<double>(stream, first, out);
}

void e57_pack(const E57Field& field, std::span<const double> values,
              std::vector<std::byte>& stream) {
  if (field.type == E57FieldType::kFloat) {
    for (const double value : values) {
      std::byte bytes[8];
      const std::size_t size = field.single_precision ? 4 : 8;
      if (field.single_precision) {
        const float single = static_cast<float>(value);
        std::memcpy(bytes, &single, 4);
      } else {
        std::memcpy(bytes, &value, 8);
      }
      stream.insert(stream.end(), bytes, bytes + size);
    }
    return;
  }
  const int bits = field.bits();
  unsigned __int128 accumulator = 0;  // holds up to 64 + 7 pending bits
  int pending = 0;
  for (const double value : values) {
    const std::uint64_t raw = static_cast<std::uint64_t>(raw_integer(field, value)) -
                              static_cast<std::uint64_t>(field.minimum);
    accumulator |= static_cast<unsigned __int128>(raw) << pending;
    pending += bits;
    while (pending >= 8) {
      stream.push_back(static_cast<std::byte>(static_cast<std::uint8_t>(accumulator)));
      accumulator >>= 8;
      pending -= 8;
    }
  }
  if (pending > 0) stream.push_back(static_cast<std::byte>(static_cast<std::uint8_t>(accumulator)));
}

}  // namespace scanbench::acquisition
