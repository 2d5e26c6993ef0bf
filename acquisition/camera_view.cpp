#include "acquisition/camera_view.hpp"

#include <array>
#include <cassert>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void fail(const fs::path& file, const std::string& key, const std::string& problem) {
  throw core::InputError(file.string(), {std::nullopt, std::nullopt, "key \"" + key + "\""},
                         problem);
}

Eigen::Vector3d vector_at(const fs::path& file, const json& root, const std::string& key) {
  if (!root.contains(key) || !root[key].is_array() || root[key].size() != 3) {
    fail(file, key, "must be an array of 3 numbers");
  }
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!root[key][k].is_number()) fail(file, key, "must be an array of 3 numbers");
    v[k] = root[key][k].get<double>();
  }
  if (!v.allFinite()) fail(file, key, "is not finite");
  return v;
}

Eigen::Isometry3d look_at_pose(const fs::path& file, const json& root) {
  const Eigen::Vector3d position = vector_at(file, root, "position");
  const Eigen::Vector3d target = vector_at(file, root, "look_at");
  const Eigen::Vector3d up =
      root.contains("up") ? vector_at(file, root, "up") : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d z = target - position;
  if (z.norm() < 1e-9) fail(file, "look_at", "equals the position");
  if (z.cross(up).norm() < 1e-9 * z.norm()) {
    fail(file, "up", "is parallel to the viewing direction");
  }
  return look_at(position, target, up);
}

Eigen::Isometry3d matrix_pose(const fs::path& file, const json& root) {
  std::array<double, 16> values{};
  try {
    values = root.at("T_world_camera").get<std::array<double, 16>>();
  } catch (const json::exception&) {
    fail(file, "T_world_camera", "must be an array of 16 numbers");
  }
  const Eigen::Matrix4d m = matrix_from_row_major(values);
  if (const std::string problem = rigid_transform_problem(m); !problem.empty()) {
    fail(file, "T_world_camera", problem);
  }
  return to_isometry(m);
}

template <typename T>
T number_at(const fs::path& file, const json& root, const std::string& key, T lo, T hi) {
  if (!root.contains(key) || !root[key].is_number()) fail(file, key, "missing or not a number");
  const T value = root[key].get<T>();
  if (!(value >= lo && value <= hi)) fail(file, key, "is out of range");
  return value;
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
  std::ifstream in(view_json, std::ios::binary);
  if (!in) throw core::InputError(view_json.string(), {}, "cannot open");
  json root;
  try {
    root = json::parse(in);
  } catch (const json::parse_error& e) {
    throw core::InputError(view_json.string(), {std::nullopt, e.byte, {}}, "not valid JSON");
  }
  if (!root.is_object()) throw core::InputError(view_json.string(), {}, "must hold a JSON object");
  CameraView view;
  view.width = number_at(view_json, root, "width", 1, 16384);
  view.height = number_at(view_json, root, "height", 1, 16384);
  view.vertical_fov_deg = number_at(view_json, root, "vertical_fov_deg", 1.0, 170.0);
  view.T_world_camera = root.contains("T_world_camera") ? matrix_pose(view_json, root)
                                                        : look_at_pose(view_json, root);
  return view;
}

}  // namespace scanbench::acquisition
