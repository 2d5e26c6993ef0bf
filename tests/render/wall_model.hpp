// A hand-built render model for the renderer's tests: a 4 m × 3 m wall in
// the plane x = 10 facing the origin, sampled every 5 cm, its left half
// red and owned by object 1, its right half blue and owned by object 2;
// both objects in group 3. Splat radii 4 cm: just over half the diagonal of
// a sample's cell, so the splats close the wall and raw points do not.
// `ground_strip` adds, unowned, one long thin splat on the ground in front
// of the wall, as distant ground gets: 8 cm across, 8 m along x.
#pragma once

#include <vector>

#include "acquisition/camera_view.hpp"
#include "render/render_model.hpp"

namespace scanbench::render::test {

// The model's origin [world]: the wall stands 10 m from it along +x.
inline const Eigen::Vector3d kOrigin(1000.0, 2000.0, 0.0);

inline RenderModel wall_model(bool hide_right = false, bool ground_strip = false) {
  RenderPoints p;
  for (int i = 0; i < 80; ++i) {
    for (int j = 0; j < 60; ++j) {
      const float y = -2.0f + 0.05f * static_cast<float>(i) + 0.025f;
      const float z = 0.05f * static_cast<float>(j) + 0.025f;
      const bool left = y > 0.0f;  // seen from the origin looking along +x, +y is left
      p.position.emplace_back(10.0f, y, z);
      p.normal.emplace_back(-1.0f, 0.0f, 0.0f);
      p.radii_m.emplace_back(0.04f, 0.04f);
      p.major_axis.push_back(Eigen::Vector3f::Zero());
      p.rgba.push_back(left ? std::array<std::uint8_t, 4>{220, 30, 30, 255}
                            : std::array<std::uint8_t, 4>{30, 30, 220, 255});
      p.intensity.push_back(0.5f);
      p.node.push_back(left ? 1u : 2u);
    }
  }
  if (ground_strip) {
    p.position.emplace_back(5.0f, 0.0f, 0.0f);
    p.normal.emplace_back(0.0f, 0.0f, 1.0f);
    p.radii_m.emplace_back(0.04f, 4.0f);
    p.major_axis.emplace_back(1.0f, 0.0f, 0.0f);
    p.rgba.push_back({90, 140, 60, 255});
    p.intensity.push_back(0.5f);
    p.node.push_back(0u);
  }
  std::vector<store::ObjectNode> tree(3);
  tree[0].id = 1;
  tree[0].parent = 3;
  tree[1].id = 2;
  tree[1].parent = 3;
  tree[1].hidden = hide_right;
  tree[2].id = 3;
  tree[2].kind = store::NodeKind::kGroup;
  return assemble_render_model(std::move(p), kOrigin, tree, {600, 1.0f});
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
