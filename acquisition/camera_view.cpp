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

constexpr std::uintmax_t kMaxPathFileBytes = 64u << 20;
constexpr std::size_t kMaxPathFrames = 1000000;

// `key` of the object at `where` ("" for the file's root, "frames[3]." for
// a path's fourth frame).
JsonPlace place_of(const fs::path& file, const std::string& key, const std::string& where = "") {
  return {file.string(), "key \"" + where + key + "\""};
}

Eigen::Vector3d vector_at(const fs::path& file, const json& object, const std::string& key,
                          const std::string& where) {
  const JsonPlace place = place_of(file, key, where);
  if (!object.contains(key) || !object[key].is_array() || object[key].size() != 3)
    place.refuse("must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k)
    v[k] =
        finite_number(object[key][k], -kMaxCoordinateM, kMaxCoordinateM, place, "each coordinate");
  return v;
}

Eigen::Isometry3d look_at_pose(const fs::path& file, const json& object, const std::string& where) {
  const Eigen::Vector3d position = vector_at(file, object, "position", where);
  const Eigen::Vector3d target = vector_at(file, object, "look_at", where);
  const Eigen::Vector3d up =
      object.contains("up") ? vector_at(file, object, "up", where) : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d z = target - position;
  if (z.norm() < 1e-9) place_of(file, "look_at", where).refuse("equals the position");
  if (z.cross(up).norm() < 1e-9 * z.norm()) {
    place_of(file, "up", where).refuse("is parallel to the viewing direction");
  }
  return look_at(position, target, up);
}

Eigen::Isometry3d matrix_pose(const fs::path& file, const json& object, const std::string& where) {
  const JsonPlace place = place_of(file, "T_world_camera", where);
  const json& values = object["T_world_camera"];
  if (!values.is_array() || values.size() != 16) place.refuse("must be an array of 16 numbers");
  std::array<double, 16> m{};
  for (std::size_t k = 0; k < 16; ++k)
    m[k] = finite_number(values[k], -kMaxCoordinateM, kMaxCoordinateM, place, "each element");
  const Eigen::Matrix4d matrix = matrix_from_row_major(m);
  if (const std::string problem = rigid_transform_problem(matrix); !problem.empty())
    place.refuse(problem);
  return to_isometry(matrix);
}

// The camera pose `object` gives: "T_world_camera", or "position" and
// "look_at" (and "up").
Eigen::Isometry3d camera_pose(const fs::path& file, const json& object, const std::string& where) {
  const Eigen::Isometry3d pose = object.contains("T_world_camera")
                                     ? matrix_pose(file, object, where)
                                     : look_at_pose(file, object, where);
  if (!pose.matrix().allFinite())
    JsonPlace{file.string(), where}.refuse("the camera's pose is not finite");
  return pose;
}

// The picture's size and angle, common to a view and a path.
CameraView camera_optics(const fs::path& file, const json& root) {
  const auto number = [&](const char* key) -> const json& {
    if (!root.contains(key)) place_of(file, key).refuse("is missing");
    return root[key];
  };
  CameraView view;
  view.width = static_cast<int>(
      whole_number(number("width"), 1, 16384, place_of(file, "width"), "the width"));
  view.height = static_cast<int>(
      whole_number(number("height"), 1, 16384, place_of(file, "height"), "the height"));
  view.vertical_fov_deg = finite_number(number("vertical_fov_deg"), 1.0, 170.0,
                                        place_of(file, "vertical_fov_deg"), "the angle");
  return view;
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
  CameraView view = camera_optics(view_json, root);
  view.T_world_camera = camera_pose(view_json, root, "");
  return view;
}

std::vector<CameraView> read_camera_path(const fs::path& path_json) {
  const json root = read_json_file(path_json, kMaxPathFileBytes);
  if (!root.is_object()) JsonPlace{path_json.string(), ""}.refuse("must hold a JSON object");
  refuse_unknown_keys(root, {"width", "height", "vertical_fov_deg", "frames"},
                      {path_json.string(), ""});
  const CameraView optics = camera_optics(path_json, root);
  if (!root.contains("frames") || !root["frames"].is_array() || root["frames"].empty() ||
      root["frames"].size() > kMaxPathFrames) {
    place_of(path_json, "frames").refuse("must be an array of 1 to 1 000 000 camera poses");
  }
  std::vector<CameraView> frames;
  frames.reserve(root["frames"].size());
  for (std::size_t k = 0; k < root["frames"].size(); ++k) {
    const json& frame = root["frames"][k];
    const std::string where = "frames[" + std::to_string(k) + "].";
    if (!frame.is_object())
      place_of(path_json, "frames[" + std::to_string(k) + "]").refuse("must be a JSON object");
    refuse_unknown_keys(frame, {"T_world_camera", "position", "look_at", "up"},
                        {path_json.string(), "key \"frames[" + std::to_string(k) + "]\""});
    CameraView view = optics;
    view.T_world_camera = camera_pose(path_json, frame, where);
    frames.push_back(view);
  }
  return frames;
}

}  // namespace scanbench::acquisition
