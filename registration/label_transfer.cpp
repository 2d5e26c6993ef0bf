#include "registration/label_transfer.hpp"

#include <cassert>
#include <cmath>
#include <numbers>

#include "core/parallel.hpp"

namespace scanbench::registration {

Sightings sight_in_source(const PreparedScan& source, const PreparedScan& target,
                          const Eigen::Isometry3d& T_source_target,
                          const LabelTransferSettings& settings) {
  const Eigen::Matrix3f R = T_source_target.linear().cast<float>();
  const Eigen::Vector3f t = T_source_target.translation().cast<float>();
  const auto range_sigmas = static_cast<float>(settings.range_sigmas);
  const auto min_normal_cos =
      static_cast<float>(std::cos(settings.max_normal_angle_deg * std::numbers::pi / 180.0));
  // The source measures p's place, the target measured p.
  const acquisition::RangeNoise& source_noise = range_noise_of(source, settings.noise);
  const acquisition::RangeNoise& target_noise = range_noise_of(target, settings.noise);
  Sightings out;
  out.pixel.assign(target.in_model.size(), -1);
  out.sighting.assign(target.in_model.size(), Sighting::kUnseen);
  const int columns = target.scan->columns;
  core::parallel_for_index(
      target.scan->rows, settings.threads,
      [&](int row) {
        for (int col = 0; col < columns; ++col) {
          const std::size_t q = target.scan->index(row, col);
          if (!target.in_model[q]) continue;
          const Eigen::Vector3f p = R * target.points[q] + t;
          const std::int64_t pixel = source.grid ? source.grid->pixel_of(p) : associate(source, p);
          if (pixel < 0) continue;
          out.pixel[q] = static_cast<std::int32_t>(pixel);  // grids hold < 2^31 pixels
          const auto k = static_cast<std::size_t>(pixel);
          const float range = p.norm();
          const float sigma_p = source_noise.sigma(range);
          const float sigma_q = target_noise.sigma(target.scan->range_m[q]);
          const float sigma = std::sqrt(sigma_p * sigma_p + sigma_q * sigma_q);
          // The place first (no normal), then the surface.
          if (!same_surface(source, k, range, sigma, nullptr, R, range_sigmas, min_normal_cos))
            continue;
          const Eigen::Vector3f* normal = target.usable[q] ? &target.geometry->normal[q] : nullptr;
          out.sighting[q] =
              same_surface(source, k, range, sigma, normal, R, range_sigmas, min_normal_cos)
                  ? Sighting::kSurface
                  : Sighting::kPlace;
        }
      },
      4);
  return out;
}

std::vector<std::uint32_t> transfer_labels(const PreparedScan& source,
                                           std::span<const std::uint32_t> labels,
                                           const PreparedScan& target,
                                           const Eigen::Isometry3d& T_source_target,
                                           const LabelTransferSettings& settings) {
  assert(labels.size() == source.in_model.size() && "one label per source pixel");
  const Sightings seen = sight_in_source(source, target, T_source_target, settings);
  std::vector<std::uint32_t> out(target.in_model.size(), 0);
  for (std::size_t q = 0; q < out.size(); ++q) {
    if (seen.sighting[q] == Sighting::kSurface)
      out[q] = labels[static_cast<std::size_t>(seen.pixel[q])];
  }
  return out;
}

}  // namespace scanbench::registration
