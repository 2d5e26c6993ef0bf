// How close a rendered picture is to the truth picture of the same camera,
// over the pixels that matter (a mask): PSNR, SSIM and the share of holes.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace scanbench::bench {

struct PictureComparison {
  double psnr_db = 0.0;        // over the masked pixels' RGB, 8-bit peak
  double ssim = 0.0;           // luminance SSIM (Gaussian window σ 1.5 px), mean over the mask
  double hole_fraction = 0.0;  // masked pixels the render left empty
  std::size_t pixels = 0;      // in the mask
};

// `ours` and `truth`: RGB, 3 bytes per pixel, row-major, width × height;
// `covered`: 1 where ours drew something; `mask`: 1 where the pixel counts.
// Asserts matching sizes.
PictureComparison compare_pictures(int width, int height, std::span<const std::uint8_t> ours,
                                   std::span<const std::uint8_t> truth,
                                   std::span<const std::uint8_t> covered,
                                   std::span<const std::uint8_t> mask);

}  // namespace scanbench::bench
