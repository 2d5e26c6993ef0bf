// A scan's panoramic image as the workbench shows it (seed 004 Fig. 2(i)):
// one channel (colour, range, intensity or normals) with each object's
// pixels tinted by its palette colour (object_palette.hpp), the selection
// being grown in yellow, and one node the user picked in cyan.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "acquisition/scan.hpp"

namespace scanbench::render {

enum class PanoramaChannel { kColor, kRange, kIntensity, kNormal };

// An RGBA8 picture, top row first.
struct Picture {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

// The layers laid over the scan; each empty, or one element per pixel.
struct PanoramaOverlays {
  std::span<const Eigen::Vector3f> normals;   // scan frame; zero where none
  std::span<const std::uint32_t> membership;  // the owning node (0: none)
  std::span<const std::uint8_t> selection;    // non-zero: selected
  std::uint32_t highlight = 0;  // a node whose pixels stand out (cyan); 0: none
};

// `scan`'s `channel`, scan.columns × scan.rows. Invalid pixels are dark
// grey; range runs from white (near) to black (far) between the 2nd and
// 98th percentiles; a scan without colour shows its intensity; normals map
// [-1, 1] to [0, 255]. Asserts each overlay is empty or per pixel.
Picture panorama_picture(const acquisition::Scan& scan, const PanoramaOverlays& overlays,
                         PanoramaChannel channel);

}  // namespace scanbench::render
