#include "modeling/lod/lod_point.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace scanbench::lod {
namespace {

float sign_not_zero(float v) {
  return v < 0.0f ? -1.0f : 1.0f;
}

std::int16_t snorm16(float v) {
  return static_cast<std::int16_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f));
}

}  // namespace

std::array<std::int16_t, 2> encode_unit(const Eigen::Vector3f& unit) {
  const float l1 = std::abs(unit.x()) + std::abs(unit.y()) + std::abs(unit.z());
  if (!(l1 > 0.0f)) return {0, 0};
  Eigen::Vector2f p(unit.x() / l1, unit.y() / l1);
  if (unit.z() < 0.0f) {  // the lower half folds over the diagonals
    p = Eigen::Vector2f((1.0f - std::abs(p.y())) * sign_not_zero(p.x()),
                        (1.0f - std::abs(p.x())) * sign_not_zero(p.y()));
  }
  return {snorm16(p.x()), snorm16(p.y())};
}

Eigen::Vector3f decode_unit(const std::array<std::int16_t, 2>& code) {
  const float x = code[0] / 32767.0f, y = code[1] / 32767.0f;
  Eigen::Vector3f v(x, y, 1.0f - std::abs(x) - std::abs(y));
  if (v.z() < 0.0f) {
    v.x() = (1.0f - std::abs(y)) * sign_not_zero(x);
    v.y() = (1.0f - std::abs(x)) * sign_not_zero(y);
  }
  return v.normalized();
}

std::uint16_t to_half(float value) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
  const std::uint32_t sign = (bits >> 16) & 0x8000u;
  const float magnitude = std::abs(value);
  if (!(magnitude < 65520.0f)) return static_cast<std::uint16_t>(sign | 0x7bffu);  // saturate
  if (magnitude < 6.103515625e-05f) {  // subnormal half: a multiple of 2^-24
    return static_cast<std::uint16_t>(
        sign | static_cast<std::uint32_t>(std::nearbyint(magnitude * 16777216.0f)));
  }
  const std::uint32_t m = std::bit_cast<std::uint32_t>(magnitude);
  // Rebias the exponent (127 → 15) and round the mantissa to 10 bits, to
  // nearest even; a carry into the exponent is the right result.
  const std::uint32_t rounded = m + 0x0fffu + ((m >> 13) & 1u);
  return static_cast<std::uint16_t>(sign | ((rounded - (112u << 23)) >> 13));
}

float from_half(std::uint16_t half) {
  const std::uint32_t sign = (std::uint32_t{half} & 0x8000u) << 16;
  const std::uint32_t exponent = (half >> 10) & 0x1fu;
  const std::uint32_t mantissa = half & 0x3ffu;
  if (exponent == 0) {
    const float v = static_cast<float>(mantissa) / 16777216.0f;
    return sign != 0 ? -v : v;
  }
  if (exponent == 31) {
    return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));
  }
  return std::bit_cast<float>(sign | ((exponent + 112u) << 23) | (mantissa << 13));
}

std::uint64_t point_priority(std::int64_t scan_id, std::uint32_t pixel) {
  // SplitMix64's finaliser over the identity: every bit of it reaches every
  // bit of the result.
  std::uint64_t z = (static_cast<std::uint64_t>(scan_id) << 32) ^ pixel;
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace scanbench::lod
