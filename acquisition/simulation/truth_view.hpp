// Ground-truth pictures of a site from a pinhole camera: the reference that
// render-quality metrics compare against.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "acquisition/simulation/scene.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"

namespace scanbench::acquisition::sim {

// Camera frame: x right, y down, z forward (the optical axis), as in OpenCV.
struct CameraView {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  double vertical_fov_deg = 60.0;
  int width = 640;
  int height = 480;
};

// Reads a view file: {"width", "height", "vertical_fov_deg", and either
// "T_world_camera": [16 numbers, row-major] or "position": [x, y, z] with
// "look_at": [x, y, z] (and optional "up", default [0, 0, 1])}. Throws
// InputError naming the file, the key and the problem.
CameraView read_camera_view(const std::filesystem::path& view_json);

struct TruthImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;    // 8-bit sRGB, row-major, 3 per pixel; sky colour where no hit
  std::vector<ObjectId> object_id;  // 0 = sky
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
