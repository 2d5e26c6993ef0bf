// A hand-built level-of-detail store for the renderer's tests: a 4 m × 3 m
// wall in the plane x = 10 (model frame) facing the origin, sampled every
// 5 cm, its left half red and owned by object 1, its right half blue and
// owned by object 2; both objects in group 3 (wall_tree). Splat radii 4 cm:
// just over half the diagonal of a sample's cell, so the splats close the
// wall and raw points do not. `ground_strip` adds, unowned, one long thin
// splat on the ground in front of the wall, as distant ground gets: 8 cm
// across, 8 m along x. Each store is written once per test executable.
#pragma once

#include <filesystem>
#include <vector>

#include "acquisition/camera_view.hpp"
#include "modeling/lod/memory_store.hpp"
#include "modeling/store/project.hpp"
#include "support/test_support.hpp"

namespace scanbench::render::test {

// The model's origin [world]: the wall stands 10 m from it along +x.
inline const Eigen::Vector3d kOrigin(1000.0, 2000.0, 0.0);

inline std::vector<lod::PointToStore> wall_points(bool ground_strip) {
  std::vector<lod::PointToStore> points;
  for (int i = 0; i < 80; ++i) {
    for (int j = 0; j < 60; ++j) {
      const double y = -2.0 + 0.05 * i + 0.025;
      const double z = 0.05 * j + 0.025;
      const bool left = y > 0.0;  // seen from the origin looking along +x, +y is left
      lod::PointToStore p;
      p.position = kOrigin + Eigen::Vector3d(10.0, y, z);
      p.normal = -Eigen::Vector3f::UnitX();
      p.radii_m = Eigen::Vector2f(0.04f, 0.04f);
      p.rgb = left ? std::array<std::uint8_t, 3>{220, 30, 30}
                   : std::array<std::uint8_t, 3>{30, 30, 220};
      p.object = left ? 1u : 2u;
      p.pixel = static_cast<std::uint32_t>(60 * i + j);
      points.push_back(p);
    }
  }
  if (ground_strip) {
    lod::PointToStore p;
    p.position = kOrigin + Eigen::Vector3d(5.0, 0.0, 0.0);
    p.normal = Eigen::Vector3f::UnitZ();
    p.radii_m = Eigen::Vector2f(0.04f, 4.0f);
    p.major_axis = Eigen::Vector3f::UnitX();
    p.rgb = std::array<std::uint8_t, 3>{90, 140, 60};
    p.pixel = 4800;
    points.push_back(p);
  }
  return points;
}

inline const std::filesystem::path& wall_store(bool ground_strip = false) {
  static const scanbench::test::ScratchDir dir;  // goes when the executable exits
  static const std::filesystem::path plain = dir / "wall.sbproj.lod";
  static const std::filesystem::path with_strip = dir / "wall_strip.sbproj.lod";
  static const bool written = [] {
    const std::vector<lod::LodScan> scans = {
        {0, 1, "wall", 0.0f, 1.0f, Eigen::Isometry3d::Identity()}};
    lod::write_lod_store(plain, kOrigin, scans, wall_points(false));
    lod::write_lod_store(with_strip, kOrigin, scans, wall_points(true));
    return true;
  }();
  static_cast<void>(written);
  return ground_strip ? with_strip : plain;
}

// The wall's objects: 1 (left) and 2 (right) in group 3.
inline std::vector<store::ObjectNode> wall_tree(bool hide_right = false) {
  std::vector<store::ObjectNode> tree(3);
  tree[0].id = 1;
  tree[0].parent = 3;
  tree[1].id = 2;
  tree[1].parent = 3;
  tree[1].hidden = hide_right;
  tree[2].id = 3;
  tree[2].kind = store::NodeKind::kGroup;
  return tree;
}

// A camera at `position` [world] looking at the wall's centre.
inline acquisition::CameraView camera_at(const Eigen::Vector3d& position, int width = 160,
                                         int height = 120, double fov_deg = 30.0) {
  acquisition::CameraView view;
  view.width = width;
  view.height = height;
  view.vertical_fov_deg = fov_deg;
  view.T_world_camera = acquisition::look_at(position, {1010.0, 2000.0, 1.5});
  return view;
}

}  // namespace scanbench::render::test
