// A pinhole camera's view of a site, and the file that gives one: what
// `scanbench simulate --render-view` ray-casts its truth pictures through and
// `scanbench render` draws the model through, so that the two compare pixel
// for pixel.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <vector>

namespace scanbench::acquisition {

// Camera frame: x right, y down, z forward (the optical axis), as in OpenCV.
// Pixel (u, v) has its centre at (u + 0.5, v + 0.5); the principal point is
// the image centre.
struct CameraView {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  double vertical_fov_deg = 60.0;
  int width = 640;
  int height = 480;

  // Focal length [pixels]: height / (2 tan(fov / 2)).
  double focal_px() const;
};

// The pose of a camera at `position` looking at `target` [m, world], its
// image's up (−y) towards `up`. Asserts target ≠ position and `up` not
// parallel to the viewing direction.
Eigen::Isometry3d look_at(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                          const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

// Reads a view file: {"width", "height", "vertical_fov_deg", and either
// "T_world_camera": [16 numbers, row-major] or "position": [x, y, z] with
// "look_at": [x, y, z] (and optional "up", default [0, 0, 1])}. Throws
// InputError naming the file, the key and the problem.
CameraView read_camera_view(const std::filesystem::path& view_json);

// Reads a camera path, a fly-through: a view file's "width", "height" and
// "vertical_fov_deg", and "frames": an array of poses, each as a view file
// gives its own ("T_world_camera", or "position" and "look_at" with an
// optional "up"). Throws InputError naming the file, the frame and the key.
std::vector<CameraView> read_camera_path(const std::filesystem::path& path_json);

}  // namespace scanbench::acquisition
