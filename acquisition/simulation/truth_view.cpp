#include "acquisition/simulation/truth_view.hpp"

#include <cmath>
#include <fstream>
#include <numbers>
#include <opencv2/core.hpp>

#include "acquisition/formats/image_file.hpp"
#include "acquisition/formats/output_file.hpp"
#include "acquisition/simulation/textures.hpp"
#include "core/errors.hpp"
#include "core/parallel.hpp"

namespace scanbench::acquisition::sim {
namespace {

namespace fs = std::filesystem;

}  // namespace

TruthImage render_truth_view(const Scene& scene, const CameraView& view,
                             const SimulationSettings& settings) {
  TruthImage image;
  image.width = view.width;
  image.height = view.height;
  const std::size_t n = static_cast<std::size_t>(view.width) * view.height;
  image.rgb.assign(3 * n, 0);
  image.object_id.assign(n, 0);
  image.distance_m.assign(n, 0.0f);
  const double focal = view.focal_px();
  const ScanLighting lighting = reference_lighting();
  const auto render_row = [&](int v) {
    for (int u = 0; u < view.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * view.width + u;
      const Eigen::Vector3d d_camera((u + 0.5 - 0.5 * view.width) / focal,
                                     (v + 0.5 - 0.5 * view.height) / focal, 1.0);
      const Ray ray{view.T_world_camera.translation(),
                    view.T_world_camera.linear() * d_camera.normalized()};
      const std::optional<Hit> hit = scene.intersect(ray, 0.0, 1e5);
      if (!hit) {
        for (int c = 0; c < 3; ++c) image.rgb[3 * i + c] = kSkyRgb[c];
        continue;
      }
      image.object_id[i] = hit->object;
      image.distance_m[i] = static_cast<float>(hit->distance_m);
      const Eigen::Vector3d point = ray.origin + hit->distance_m * ray.direction;
      const double footprint =
          footprint_radius(hit->distance_m, 1.0 / focal, std::abs(hit->normal.dot(ray.direction)));
      const auto rgb =
          expose(shade(scene, *hit, point, lighting, true, surface_albedo(scene, *hit, footprint)),
                 lighting);
      for (int c = 0; c < 3; ++c) image.rgb[3 * i + c] = rgb[c];
    }
  };
  core::parallel_for_index(view.height, settings.threads, render_row);
  return image;
}

void write_truth_image(const TruthImage& image, const fs::path& png) {
  cv::Mat bgr(image.height, image.width, CV_8UC3), ids(image.height, image.width, CV_16UC1);
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * image.width + u;
      bgr.at<cv::Vec3b>(v, u) =
          cv::Vec3b(image.rgb[3 * i + 2], image.rgb[3 * i + 1], image.rgb[3 * i]);
      ids.at<std::uint16_t>(v, u) = image.object_id[i];
    }
  }
  const fs::path id_png = png.parent_path() / (png.stem().string() + "_object_id.png");
  write_files_together({{png, encode_image(png, bgr)}, {id_png, encode_image(id_png, ids)}});
}

}  // namespace scanbench::acquisition::sim
