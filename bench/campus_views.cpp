#include "bench/campus_views.hpp"

#include <algorithm>
#include <span>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/spherical_grid.hpp"

namespace scanbench::bench {

acquisition::CameraView look(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                             double fov_deg, int width, int height) {
  acquisition::CameraView view;
  view.width = width;
  view.height = height;
  view.vertical_fov_deg = fov_deg;
  view.T_world_camera = acquisition::look_at(position, target);
  return view;
}

std::vector<NamedView> campus_views(int width, int height) {
  return {{"closeup", look({12.5, -15.0, 3.0}, {21.0, -11.0, 4.0}, 60.0, width, height)},
          {"street", look({-22.0, -2.0, 1.7}, {30.0, 8.0, 3.0}, 60.0, width, height)},
          {"overview", look({-55.0, -60.0, 55.0}, {0.0, 0.0, 0.0}, 50.0, width, height)}};
}

std::vector<std::uint8_t> sampled_mask(const acquisition::sim::TruthImage& truth,
                                       const acquisition::CameraView& camera,
                                       const SimulatedSite& site,
                                       std::optional<std::size_t> first_scans) {
  const std::span<const acquisition::Scan> scans(
      site.scans.data(), std::min(site.scans.size(), first_scans.value_or(site.scans.size())));
  std::vector<acquisition::SphericalGrid> grids;
  for (const acquisition::Scan& scan : scans) grids.emplace_back(scan);
  const double focal = camera.focal_px();
  std::vector<std::uint8_t> mask(truth.distance_m.size(), 0);
  for (int v = 0; v < truth.height; ++v) {
    for (int u = 0; u < truth.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * truth.width + u;
      if (truth.distance_m[i] <= 0.0f) continue;
      const Eigen::Vector3d ray((u + 0.5 - 0.5 * truth.width) / focal,
                                (v + 0.5 - 0.5 * truth.height) / focal, 1.0);
      const Eigen::Vector3d p = camera.T_world_camera * (ray.normalized() * truth.distance_m[i]);
      for (std::size_t s = 0; s < scans.size() && !mask[i]; ++s) {
        const Eigen::Vector3d local = scans[s].T_world_scan.inverse() * p;
        const std::int64_t pixel = grids[s].pixel_of(local);
        if (pixel < 0 ||
            !acquisition::in_model(scans[s], site.geometry[s], static_cast<std::size_t>(pixel)))
          continue;
        const auto k = static_cast<std::size_t>(pixel);
        const Eigen::Vector3d sample =
            scans[s].range_m[k] * local.normalized();  // on the beam p lies on
        mask[i] = (sample - local).norm() <= 0.02 + 2.0 * site.geometry[s].footprint_m[k];
      }
    }
  }
  return mask;
}

}  // namespace scanbench::bench
