#include "bench/image_metrics.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

namespace scanbench::bench {

namespace {

using Plane = std::vector<float>;

Plane luminance(int width, int height, std::span<const std::uint8_t> rgb) {
  Plane y(static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < y.size(); ++i)
    y[i] = 0.299f * rgb[3 * i] + 0.587f * rgb[3 * i + 1] + 0.114f * rgb[3 * i + 2];
  return y;
}

// Separable Gaussian blur (σ 1.5, 11 taps), edges clamped: SSIM's window.
Plane blur(int width, int height, const Plane& in) {
  std::array<float, 11> taps{};
  float sum = 0.0f;
  for (int k = -5; k <= 5; ++k) sum += taps[k + 5] = std::exp(-0.5f * k * k / (1.5f * 1.5f));
  for (float& t : taps) t /= sum;
  Plane across(in.size()), out(in.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float v = 0.0f;
      for (int k = -5; k <= 5; ++k)
        v +=
            taps[k + 5] * in[static_cast<std::size_t>(y) * width + std::clamp(x + k, 0, width - 1)];
      across[static_cast<std::size_t>(y) * width + x] = v;
    }
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float v = 0.0f;
      for (int k = -5; k <= 5; ++k)
        v += taps[k + 5] *
             across[static_cast<std::size_t>(std::clamp(y + k, 0, height - 1)) * width + x];
      out[static_cast<std::size_t>(y) * width + x] = v;
    }
  }
  return out;
}

Plane product(const Plane& a, const Plane& b) {
  Plane out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] * b[i];
  return out;
}

}  // namespace

PictureComparison compare_pictures(int width, int height, std::span<const std::uint8_t> ours,
                                   std::span<const std::uint8_t> truth,
                                   std::span<const std::uint8_t> covered,
                                   std::span<const std::uint8_t> mask) {
  const std::size_t n = static_cast<std::size_t>(width) * height;
  assert(ours.size() == 3 * n && truth.size() == 3 * n && covered.size() == n && mask.size() == n);
  PictureComparison out;
  double squared = 0.0;
  std::size_t holes = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    ++out.pixels;
    holes += covered[i] == 0;
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(ours[3 * i + c]) - truth[3 * i + c];
      squared += d * d;
    }
  }
  if (out.pixels == 0) return out;
  const double mse = squared / (3.0 * static_cast<double>(out.pixels));
  out.psnr_db = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 99.0;
  out.hole_fraction = static_cast<double>(holes) / static_cast<double>(out.pixels);
  // SSIM (Wang et al. 2004) on luminance, K1 = 0.01, K2 = 0.03, L = 255.
  const Plane x = luminance(width, height, ours), y = luminance(width, height, truth);
  const Plane mx = blur(width, height, x), my = blur(width, height, y);
  const Plane xx = blur(width, height, product(x, x)), yy = blur(width, height, product(y, y));
  const Plane xy = blur(width, height, product(x, y));
  constexpr double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  double ssim = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    const double vx = xx[i] - mx[i] * mx[i], vy = yy[i] - my[i] * my[i];
    const double cov = xy[i] - mx[i] * my[i];
    ssim += ((2.0 * mx[i] * my[i] + c1) * (2.0 * cov + c2)) /
            ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
  }
  out.ssim = ssim / static_cast<double>(out.pixels);
  return out;
}

}  // namespace scanbench::bench
