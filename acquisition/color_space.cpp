#include "acquisition/color_space.hpp"

#include <algorithm>
#include <cmath>

namespace scanbench::acquisition {

namespace {

// Linear sRGB → CIE XYZ (D65), and its inverse.
const Eigen::Matrix3d& rgb_to_xyz() {
  static const Eigen::Matrix3d m = (Eigen::Matrix3d() << 0.4124564, 0.3575761, 0.1804375,  //
                                    0.2126729, 0.7151522, 0.0721750,                       //
                                    0.0193339, 0.1191920, 0.9503041)
                                       .finished();
  return m;
}

const Eigen::Matrix3d& xyz_to_rgb() {
  static const Eigen::Matrix3d m = rgb_to_xyz().inverse();
  return m;
}

// The D65 white point's XYZ (Y = 1): the row sums of rgb_to_xyz, so that
// linear white (1, 1, 1) is L* 100, a* b* 0 exactly.
const Eigen::Vector3d& white() {
  static const Eigen::Vector3d w = rgb_to_xyz().rowwise().sum();
  return w;
}

constexpr double kDelta = 6.0 / 29.0;

double lab_f(double t) {
  return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3.0 * kDelta * kDelta) + 4.0 / 29.0;
}

double lab_f_inverse(double f) {
  return f > kDelta ? f * f * f : 3.0 * kDelta * kDelta * (f - 4.0 / 29.0);
}

std::array<float, 256> make_linear_table() {
  std::array<float, 256> table{};
  for (int v = 0; v < 256; ++v) {
    const double c = v / 255.0;
    table[static_cast<std::size_t>(v)] =
        static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
  }
  return table;
}

}  // namespace

float srgb_to_linear(std::uint8_t value) {
  static const std::array<float, 256> table = make_linear_table();
  return table[value];
}

std::uint8_t linear_to_srgb(double linear) {
  const double c = std::clamp(linear, 0.0, 1.0);
  const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::lround(255.0 * encoded));
}

Eigen::Vector3d linear_rgb_to_lab(const Eigen::Vector3d& rgb) {
  const Eigen::Vector3d xyz = (rgb_to_xyz() * rgb).cwiseQuotient(white());
  const double fx = lab_f(xyz.x()), fy = lab_f(xyz.y()), fz = lab_f(xyz.z());
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Eigen::Vector3d lab_to_linear_rgb(const Eigen::Vector3d& lab) {
  const double fy = (lab.x() + 16.0) / 116.0;
  const double fx = fy + lab.y() / 500.0;
  const double fz = fy - lab.z() / 200.0;
  const Eigen::Vector3d xyz(lab_f_inverse(fx), lab_f_inverse(fy), lab_f_inverse(fz));
  return xyz_to_rgb() * xyz.cwiseProduct(white());
}

Eigen::Vector3d srgb_to_linear_rgb(const std::array<std::uint8_t, 3>& rgb) {
  return {srgb_to_linear(rgb[0]), srgb_to_linear(rgb[1]), srgb_to_linear(rgb[2])};
}

std::array<std::uint8_t, 3> linear_rgb_to_srgb(const Eigen::Vector3d& rgb) {
  return {linear_to_srgb(rgb.x()), linear_to_srgb(rgb.y()), linear_to_srgb(rgb.z())};
}

Eigen::Vector3d srgb_to_lab(const std::array<std::uint8_t, 3>& rgb) {
  return linear_rgb_to_lab(srgb_to_linear_rgb(rgb));
}

std::array<std::uint8_t, 3> lab_to_srgb(const Eigen::Vector3d& lab) {
  return linear_rgb_to_srgb(lab_to_linear_rgb(lab));
}

}  // namespace scanbench::acquisition
