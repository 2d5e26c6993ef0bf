// Colour spaces of scan colours: 8-bit sRGB as scanners store it, linear
// RGB (sRGB primaries, IEC 61966-2-1) where light adds up and exposure and
// white balance are gains, and CIE 1976 L*a*b* (D65 white) where distances
// are perceptual (ΔE) and colour edits are made.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace scanbench::acquisition {

// sRGB decoding of an 8-bit value: linear [0, 1] (a table lookup).
float srgb_to_linear(std::uint8_t value);

// sRGB encoding of a linear value, clamped to [0, 1] and rounded to 8 bits.
std::uint8_t linear_to_srgb(double linear);

// Linear RGB → L*a*b* and back (D65; L* in [0, 100] for colours in gamut).
Eigen::Vector3d linear_rgb_to_lab(const Eigen::Vector3d& rgb);
Eigen::Vector3d lab_to_linear_rgb(const Eigen::Vector3d& lab);

// 8-bit sRGB → linear RGB, and linear RGB → 8-bit sRGB (clamped, rounded).
Eigen::Vector3d srgb_to_linear_rgb(const std::array<std::uint8_t, 3>& rgb);
std::array<std::uint8_t, 3> linear_rgb_to_srgb(const Eigen::Vector3d& rgb);

// 8-bit sRGB → L*a*b*.
Eigen::Vector3d srgb_to_lab(const std::array<std::uint8_t, 3>& rgb);
// L*a*b* → 8-bit sRGB, out-of-gamut channels clamped.
std::array<std::uint8_t, 3> lab_to_srgb(const Eigen::Vector3d& lab);

// A colour correction in linear RGB, where exposure and white balance are
// gains: rgb' = matrix · rgb + offset. registration/color_harmonization.hpp
// solves one per scan; the project stores it, and the model shows colours
// through it.
struct ColorCorrection {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& rgb) const { return matrix * rgb + offset; }
  bool identity() const {
    return matrix == Eigen::Matrix3d::Identity() && offset == Eigen::Vector3d::Zero();
  }
  bool operator==(const ColorCorrection&) const = default;
};

// CIE 1976 colour difference: the Euclidean distance in L*a*b*.
inline double delta_e(const Eigen::Vector3d& lab_a, const Eigen::Vector3d& lab_b) {
  return (lab_a - lab_b).norm();
}

}  // namespace scanbench::acquisition
