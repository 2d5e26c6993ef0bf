#include "acquisition/simulation/virtual_scanner.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/textures.hpp"
#include "core/parallel.hpp"

namespace scanbench::acquisition::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// What the beam centre of one pixel sees, before noise and mixing.
struct CleanSample {
  bool hit = false;
  float range_m = 0.0f;
  ObjectId object = 0;
  Eigen::Vector3f normal_scan = Eigen::Vector3f::Zero();
  Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
  float intensity = 0.0f;  // noise-free
};

SphericalAngles scanner_angles(const ScannerModel& model) {
  const double az_step = 2.0 * std::numbers::pi / model.columns;
  const double el_step = (model.elevation_max_deg - model.elevation_min_deg) * kDeg / model.rows;
  // Azimuth decreases along a row: the scanner turns clockwise seen from
  // above, so the panorama reads left to right like a photograph, not mirrored.
  return {-0.5 * az_step, -az_step, model.elevation_max_deg * kDeg - 0.5 * el_step, -el_step};
}

Eigen::Vector3d direction_at(const SphericalAngles& a, double row, double col) {
  const double az = a.azimuth_start_rad + col * a.azimuth_step_rad;
  const double el = a.elevation_start_rad + row * a.elevation_step_rad;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

float clean_intensity(const Hit& hit, double reflectance, double cos_incidence,
                      const ScannerModel& model) {
  const double falloff = std::sqrt(model.intensity_reference_range_m /
                                   std::max(hit.distance_m, model.intensity_reference_range_m));
  return static_cast<float>(std::clamp(reflectance * cos_incidence * falloff, 0.0, 1.0));
}

// Casts one beam (fractional grid position) and describes what it sees.
CleanSample cast_beam(const Scene& scene, const Eigen::Isometry3d& T_world_scan,
                      const SphericalAngles& angles, double row, double col,
                      const ScannerModel& model, const ScanLighting& lighting) {
  const Eigen::Vector3d d_scan = direction_at(angles, row, col);
  const Ray ray{T_world_scan.translation(), T_world_scan.linear() * d_scan};
  const std::optional<Hit> hit = scene.intersect(ray, model.min_range_m, model.max_range_m);
  CleanSample sample;
  if (!hit) return sample;
  sample.hit = true;
  sample.range_m = static_cast<float>(hit->distance_m);
  sample.object = hit->object;
  sample.normal_scan = (T_world_scan.linear().transpose() * hit->normal).cast<float>();
  const Eigen::Vector3d point = ray.origin + hit->distance_m * ray.direction;
  const double cos_incidence = std::abs(hit->normal.dot(ray.direction));
  const double pixel_angle =
      std::max(std::abs(angles.azimuth_step_rad), std::abs(angles.elevation_step_rad));
  const double footprint = footprint_radius(hit->distance_m, pixel_angle, cos_incidence);
  const SurfaceAppearance look = surface_appearance(scene, *hit, footprint);
  sample.radiance = shade(scene, *hit, point, lighting, model.shadows, look.albedo);
  sample.intensity = clean_intensity(*hit, look.reflectance, cos_incidence, model);
  return sample;
}

bool is_gap(float a, float b, const ScannerModel& model) {
  const double gap =
      std::max(model.discontinuity_min_gap_m, model.discontinuity_relative_gap * std::min(a, b));
  return std::abs(a - b) > gap;
}

// A pixel at a depth discontinuity: some 4-neighbour sees a surface at a
// clearly different range (a neighbour without return is no discontinuity:
// the sky returns nothing to mix with).
bool at_discontinuity(const std::vector<CleanSample>& clean, const ScannerModel& model, int row,
                      int col) {
  const CleanSample& centre = clean[static_cast<std::size_t>(row) * model.columns + col];
  if (!centre.hit) return false;
  const int offsets[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  for (const auto& o : offsets) {
    const int r = row + o[0];
    const int c = (col + o[1] + model.columns) % model.columns;  // the panorama wraps
    if (r < 0 || r >= model.rows) continue;
    const CleanSample& n = clean[static_cast<std::size_t>(r) * model.columns + c];
    if (n.hit && is_gap(centre.range_m, n.range_m, model)) return true;
  }
  return false;
}

// The blended echo of a beam whose footprint straddles an edge: the beam
// centre plus four samples at the corners of the pixel cell, averaged over
// the samples that return. A footprint counts as straddling only when some
// sample lies off the centre's tangent plane by more than the discontinuity
// gap (a wall seen at a grazing angle changes range fast but is one surface),
// and the blend counts only when it leaves the true surface by more than
// three noise sigmas. Returns false otherwise.
bool mixed_echo(const Scene& scene, const Eigen::Isometry3d& T_world_scan,
                const SphericalAngles& angles, int row, int col, const ScannerModel& model,
                const ScanLighting& lighting, const CleanSample& centre, CleanSample& echo) {
  const double corners[4][2] = {{-0.5, -0.5}, {-0.5, 0.5}, {0.5, -0.5}, {0.5, 0.5}};
  const Eigen::Vector3d centre_point = centre.range_m * direction_at(angles, row, col);
  const Eigen::Vector3d normal = centre.normal_scan.cast<double>();
  bool straddles = false;
  echo = centre;
  int returns = 1;
  for (const auto& corner : corners) {
    const double r = row + corner[0], c = col + corner[1];
    const CleanSample s = cast_beam(scene, T_world_scan, angles, r, c, model, lighting);
    if (!s.hit) continue;
    const Eigen::Vector3d point = s.range_m * direction_at(angles, r, c);
    const double off_plane = std::abs(normal.dot(point - centre_point));
    straddles =
        straddles || off_plane > std::max(model.discontinuity_min_gap_m,
                                          model.discontinuity_relative_gap * centre.range_m);
    echo.range_m += s.range_m;
    echo.intensity += s.intensity;
    echo.radiance += s.radiance;
    ++returns;
  }
  echo.range_m /= static_cast<float>(returns);
  echo.intensity /= static_cast<float>(returns);
  echo.radiance /= static_cast<float>(returns);
  const double sigma = model.range_noise.sigma(static_cast<double>(centre.range_m));
  return straddles && std::abs(echo.range_m - centre.range_m) > 3.0 * sigma;
}

template <typename Body>
void parallel_rows(int rows, const SimulationSettings& settings, Body&& body) {
  core::parallel_for_index(rows, settings.threads, body);
}

}  // namespace

const char* noise_profile_name(NoiseProfile profile) {
  switch (profile) {
    case NoiseProfile::kPulsed:
      return "pulsed";
    case NoiseProfile::kPhaseShift:
      return "phase-shift";
    case NoiseProfile::kStructuredLight:
      return "structured-light";
  }
  return "pulsed";
}

ScannerModel with_noise_profile(ScannerModel model, NoiseProfile profile) {
  switch (profile) {
    case NoiseProfile::kPulsed:
      model.range_noise = RangeNoise{0.005, 5e-5, 0.0};
      model.min_range_m = 1.0;
      model.max_range_m = 200.0;
      break;
    case NoiseProfile::kPhaseShift:
      model.range_noise = RangeNoise{0.0006, 2e-5, 2e-6};
      model.min_range_m = 0.6;
      model.max_range_m = 120.0;
      break;
    case NoiseProfile::kStructuredLight:
      model.range_noise = RangeNoise{0.0, 0.0, 1.5e-3};
      model.min_range_m = 0.5;
      model.max_range_m = 8.0;
      break;
  }
  return model;
}

ScanLighting reference_lighting() {
  return ScanLighting{};
}

ScanLighting random_lighting(std::uint64_t seed) {
  Random rng(hash_combine(seed, 0x116417));
  const double elevation = rng.uniform(20.0, 65.0) * kDeg;
  const double azimuth = rng.uniform(0.0, 360.0) * kDeg;
  ScanLighting lighting;
  lighting.sun_direction_world =
      Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                      std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  lighting.exposure = rng.uniform(0.45, 0.8);
  for (int c = 0; c < 3; ++c)
    lighting.white_balance[c] = static_cast<float>(rng.uniform(0.88, 1.12));
  return lighting;
}

ScanLighting one_sun_lighting(std::uint64_t seed) {
  ScanLighting out = reference_lighting();
  const ScanLighting own = random_lighting(seed);
  out.exposure = own.exposure;
  out.white_balance = own.white_balance;
  return out;
}

double footprint_radius(double range_m, double pixel_angle_rad, double cos_incidence) {
  return 0.5 * range_m * pixel_angle_rad / std::max(cos_incidence, 0.1);
}

Eigen::Vector3f shade(const Scene& scene, const Hit& hit, const Eigen::Vector3d& point_world,
                      const ScanLighting& lighting, bool shadows, const Eigen::Vector3f& albedo) {
  const double facing = hit.normal.dot(lighting.sun_direction_world);
  double sun = 0.0;
  if (facing > 0.0) {
    const Ray to_sun{point_world + 1e-4 * hit.normal, lighting.sun_direction_world};
    const bool lit = !shadows || !scene.intersect(to_sun, 0.0, 1e4).has_value();
    sun = lit ? lighting.sun_irradiance * facing : 0.0;
  }
  return albedo * static_cast<float>(lighting.sky_irradiance + sun);
}

Eigen::Matrix<std::uint8_t, 3, 1> expose(const Eigen::Vector3f& radiance,
                                         const ScanLighting& lighting) {
  Eigen::Matrix<std::uint8_t, 3, 1> rgb;
  for (int c = 0; c < 3; ++c) {
    const double linear =
        std::clamp(radiance[c] * lighting.exposure * lighting.white_balance[c], 0.0, 1.0);
    const double encoded =
        linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
    rgb[c] = static_cast<std::uint8_t>(std::lround(255.0 * encoded));
  }
  return rgb;
}

SimulatedScan simulate_scan(const Scene& scene, const Eigen::Isometry3d& T_world_scan,
                            const ScannerModel& model, const ScanLighting& lighting,
                            std::uint64_t seed, const SimulationSettings& settings) {
  assert(model.rows > 0 && model.columns > 0 && model.min_range_m < model.max_range_m);
  const SphericalAngles angles = scanner_angles(model);
  const std::size_t n = static_cast<std::size_t>(model.rows) * model.columns;
  std::vector<CleanSample> clean(n);
  parallel_rows(model.rows, settings, [&](int row) {
    for (int col = 0; col < model.columns; ++col) {
      clean[static_cast<std::size_t>(row) * model.columns + col] =
          cast_beam(scene, T_world_scan, angles, row, col, model, lighting);
    }
  });

  SimulatedScan out;
  Scan& scan = out.scan;
  scan = make_empty_scan(model.rows, model.columns, true, true);
  scan.angles = angles;
  scan.T_world_scan = T_world_scan;
  scan.scanner.name = model.name;
  scan.scanner.position_world = T_world_scan.translation();
  ScanTruth& truth = out.truth;
  truth.object_id.assign(n, 0);
  truth.normal_scan.assign(n, Eigen::Vector3f::Zero());
  truth.range_m.assign(n, 0.0f);
  truth.mixed.assign(n, 0);

  parallel_rows(model.rows, settings, [&](int row) {
    for (int col = 0; col < model.columns; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * model.columns + col;
      const CleanSample& centre = clean[i];
      if (!centre.hit) continue;
      Random rng(hash_combine(seed, i));
      CleanSample measured = centre;
      if (at_discontinuity(clean, model, row, col) &&
          rng.uniform() < model.mixed_pixel_probability) {
        CleanSample echo;
        if (mixed_echo(scene, T_world_scan, angles, row, col, model, lighting, centre, echo)) {
          measured = echo;
          truth.mixed[i] = 1;
        }
      }
      truth.object_id[i] = centre.object;
      truth.normal_scan[i] = centre.normal_scan;
      truth.range_m[i] = centre.range_m;
      const double sigma = model.range_noise.sigma(static_cast<double>(measured.range_m));
      scan.range_m[i] = static_cast<float>(measured.range_m + sigma * rng.normal());
      scan.valid[i] = scan.range_m[i] > 0.0f;
      scan.intensity[i] = static_cast<float>(
          std::clamp(measured.intensity * (1.0 + model.intensity_noise * rng.normal()), 0.0, 1.0));
      const auto rgb = expose(measured.radiance, lighting);
      for (int c = 0; c < 3; ++c) scan.rgb[3 * i + c] = rgb[c];
    }
  });
  return out;
}

}  // namespace scanbench::acquisition::sim
