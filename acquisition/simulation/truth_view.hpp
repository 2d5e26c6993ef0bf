// Ground-truth pictures of a site from a pinhole camera: the reference that
// render-quality metrics compare against.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "acquisition/camera_view.hpp"
#include "acquisition/simulation/scene.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"

namespace scanbench::acquisition::sim {

using acquisition::CameraView;
using acquisition::read_camera_view;

// The sky's colour in truth pictures (sRGB): the background a renderer
// compared against them should draw.
inline constexpr std::uint8_t kSkyRgb[3] = {170, 200, 235};

struct TruthImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;    // 8-bit sRGB, row-major, 3 per pixel; sky colour where no hit
  std::vector<ObjectId> object_id;  // 0 = sky
  std::vector<float> distance_m;    // camera centre to the hit along the pixel's ray; 0 = sky
};

// Ray-casts the scene through every pixel centre under reference_lighting()
// (with shadows). Deterministic.
TruthImage render_truth_view(const Scene& scene, const CameraView& view,
                             const SimulationSettings& settings = {});

// Writes the colour image to `png` and the 16-bit object ids beside it as
// "<stem>_object_id.png", both or neither (as acquisition::write_files_together). Throws
// core::InputError for an output that cannot be one (a folder, a project),
// core::RuntimeFailure naming the file when it cannot be written.
void write_truth_image(const TruthImage& image, const std::filesystem::path& png);

}  // namespace scanbench::acquisition::sim
