// The record encodings of an E57 compressed vector (ASTM E2807 §9): each
// field of the prototype is one bytestream. Integer and ScaledInteger
// values are stored as (value − minimum) in the fewest bits that hold
// maximum − minimum, packed least significant bit first into a continuous
// little-endian bit stream; Float values are raw little-endian IEEE 754
// numbers of 4 or 8 bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace scanbench::acquisition {

enum class E57FieldType { kInteger, kScaledInteger, kFloat };

// One field of a compressed vector's prototype.
struct E57Field {
  std::string name;  // "sphericalRange", "colorRed", …
  E57FieldType type = E57FieldType::kFloat;
  // Integer and ScaledInteger: the stored integers' bounds; the value is
  // raw × scale + offset for a ScaledInteger.
  std::int64_t minimum = 0;
  std::int64_t maximum = 0;
  double scale = 1.0;
  double offset = 0.0;
  // Float: 4-byte numbers when true, else 8-byte; the bounds are advisory.
  bool single_precision = false;
  double float_minimum = 0.0;
  double float_maximum = 0.0;

  // Bits per record in the bytestream: 32 or 64 for a Float, else
  // ⌈log2(maximum − minimum + 1)⌉ (0 when minimum == maximum).
  int bits() const;
};

// The bytes `records` records of `field` take (rounded up to whole bytes).
std::uint64_t e57_stream_bytes(const E57Field& field, std::uint64_t records);

// Decodes records first … first + out.size() − 1 of `stream` into values
// (scaled and offset for a ScaledInteger). Returns false when the stream is
// too short.
bool e57_unpack(const E57Field& field, std::span<const std::byte> stream, std::uint64_t first,
                std::span<double> out);

// Appends the encoding of `values` to `stream`, which must end on a whole
// record boundary that is also a whole byte (callers write records in
// multiples of 8). Integer values are rounded to the nearest raw integer and
// clamped into [minimum, maximum].
void e57_pack(const E57Field& field, std::span<const double> values,
              std::vector<std::byte>& stream);

}  // namespace scanbench::acquisition
