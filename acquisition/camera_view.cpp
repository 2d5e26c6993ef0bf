#include "acquisition/camera_view.hpp"

#include <array>
#include <cassert>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "acquisition/formats/json_input.hpp"
#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A camera farther out than this is a typo, not a site [m]; as the scan
// readers' bound on coordinates.
constexpr double kMaxCoordinateM = 1e8;

constexpr std::uintmax_t kMaxViewFileBytes = 1u << 20;

JsonPlace place_of(const fs::path& file, const std::string& key) {
  return {file.string(), "key \"" + key + "\""};
}

Eigen::Vector3d vector_at(const fs::path& file, const json& root, const std::string& key) {
  const JsonPlace place = place_of(file, key);
  if (!root.contains(key) || !root[key].is_array() || root[key].size() != 3)
    place.refuse("must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k)
    v[k] = finite_number(root[key][k], -kMaxCoordinateM, kMaxCoordinateM, place, "each coordinate");
  return v;
}

Eigen::Isometry3d look_at_pose(const fs::path& file, const json& root) {
  const Eigen::Vector3d position = vector_at(file, root, "position");
  const Eigen::Vector3d target = vector_at(file, root, "look_at");
  const Eigen::Vector3d up =
      root.contains("up") ? vector_at(file, root, "up") : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d z = target - position;
  if (z.norm() < 1e-9) place_of(file, "look_at").refuse("equals the position");
  if (z.cross(up).norm() < 1e-9 * z.norm()) {
    place_of(file, "up").refuse("is parallel to the viewing direction");
  }
  return look_at(position, target, up);
}

Eigen::Isometry3d matrix_pose(const fs::path& file, const json& root) {
  const JsonPlace place = place_of(file, "T_world_camera");
  const json& values = root["T_world_camera"];
  if (!values.is_array() || values.size() != 16) place.refuse("must be an array of 16 numbers");
  std::array<double, 16> m{};
  for (std::size_t k = 0; k < 16; ++k)
    m[k] = finite_number(values[k], -kMaxCoordinateM, kMaxCoordinateM, place, "each element");
  const Eigen::Matrix4d matrix = matrix_from_row_major(m);
  if (const std::string problem = rigid_transform_problem(matrix); !problem.empty())
    place.refuse(problem);
  return to_isometry(matrix);
}

}  // namespace

Eigen::Isometry3d look_at(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                          const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = target - position;
  const Eigen::Vector3d x = z.cross(up);
  assert(z.norm() >= 1e-9 && x.norm() >= 1e-9 * z.norm() && "a degenerate look-at");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = x.normalized();
  pose.linear().col(2) = z.normalized();
  pose.linear().col(1) = pose.linear().col(2).cross(pose.linear().col(0));
  pose.translation() = position;
  return pose;
}

double CameraView::focal_px() const {
  return 0.5 * height / std::tan(0.5 * vertical_fov_deg * std::numbers::pi / 180.0);
}

CameraView read_camera_view(const fs::path& view_json) {
  const json root = read_json_file(view_json, kMaxViewFileBytes);
  if (!root.is_object()) JsonPlace{view_json.string(), ""}.refuse("must hold a JSON object");
  refuse_unknown_keys(
      root, {"width", "height", "vertical_fov_deg", "T_world_camera", "position", "look_at", "up"},
      {view_json.string(), ""});
  const auto number = [&](const char* key) -> const json& {
    if (!root.contains(key)) place_of(view_json, key).refuse("is missing");
    return root[key];
  };
  CameraView view;
  view.width = static_cast<int>(
      whole_number(number("width"), 1, 16384, place_of(view_json, "width"), "the width"));
  view.height = static_cast<int>(
      whole_number(number("height"), 1, 16384, place_of(view_json, "height"), "the height"));
  view.vertical_fov_deg = finite_number(number("vertical_fov_deg"), 1.0, 170.0,
                                        place_of(view_json, "vertical_fov_deg"), "the angle");
  view.T_world_camera = root.contains("T_world_camera") ? matrix_pose(view_json, root)
                                                        : look_at_pose(view_json, root);
  if (!view.T_world_camera.matrix().allFinite())
    JsonPlace{view_json.string(), ""}.refuse("the camera's pose is not finite");
  return view;
}

}  // namespace scanbench::acquisition
