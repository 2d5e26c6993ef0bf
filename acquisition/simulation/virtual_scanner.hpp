// The virtual panoramic laser scanner: ray-casts a Scene on the regular
// azimuth × elevation grid of a RIEGL LMS-Z360-like instrument (seed 004 §3)
// and returns the scan it would deliver — noisy range, intensity, colour under
// the scan's own lighting, mixed pixels at depth discontinuities — together
// with the exact truth behind every pixel.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "acquisition/range_noise.hpp"
#include "acquisition/scan.hpp"
#include "acquisition/simulation/scene.hpp"

namespace scanbench::acquisition::sim {

struct ScannerModel {
  std::string name = "virtual LMS-Z360";
  int columns = 3600;                // full 360° of azimuth: step = 360° / columns
  int rows = 900;                    // the elevation window: step = window / rows
  double elevation_min_deg = -40.0;  // lower edge of the window
  double elevation_max_deg = 50.0;   // upper edge of the window
  double min_range_m = 1.0;          // closer surfaces give no return
  double max_range_m = 200.0;        // farther surfaces give no return
  // Range noise: Gaussian with standard deviation σ(range).
  RangeNoise range_noise;
  // Share of depth-discontinuity pixels whose beam returns one blended echo
  // (a "mixed pixel" floating between foreground and background) instead of
  // the surface under the beam centre.
  double mixed_pixel_probability = 0.5;
  // A discontinuity is a range jump above max(min_gap_m, relative_gap · range).
  double discontinuity_min_gap_m = 0.1;
  double discontinuity_relative_gap = 0.02;
  // Relative Gaussian noise of the intensity reading.
  double intensity_noise = 0.02;
  // Intensity is reflectance · cos(incidence) · sqrt(reference / max(range,
  // reference)): the partial range compensation scanners apply before they
  // report a [0, 1] intensity.
  double intensity_reference_range_m = 10.0;
  bool shadows = true;  // sun shadows in the colour image
};

// The range noise of three kinds of instrument, for `scanbench simulate
// --noise` and the geometry bench:
//   pulsed            time of flight (RIEGL LMS-Z360, the default):
//                     σ = 5 mm + 5·10⁻⁵ r, 1–200 m;
//   phase-shift       low noise near, growing with the weaker return far
//                     away: σ = 0.6 mm + 2·10⁻⁵ r + 2·10⁻⁶ r², 0.6–120 m;
//   structured-light  triangulation, whose depth error grows with r²:
//                     σ = 1.5·10⁻³ r², 0.5–8 m.
enum class NoiseProfile { kPulsed, kPhaseShift, kStructuredLight };

inline constexpr std::array<NoiseProfile, 3> kNoiseProfiles = {
    NoiseProfile::kPulsed, NoiseProfile::kPhaseShift, NoiseProfile::kStructuredLight};

// "pulsed", "phase-shift", "structured-light".
const char* noise_profile_name(NoiseProfile profile);

// `model` with the profile's range noise and range limits.
ScannerModel with_noise_profile(ScannerModel model, NoiseProfile profile);

// Lighting of one scan's colour image. Each scan of a campaign gets its own,
// so scans of the same wall disagree in colour (seed 004 §4.5).
struct ScanLighting {
  Eigen::Vector3d sun_direction_world =
      Eigen::Vector3d(0.3, 0.2, 0.93).normalized();  // towards the sun
  double sun_irradiance = 2.5;  // linear units; albedo 1 facing the sun → 2.5 · exposure
  double sky_irradiance = 0.6;  // ambient, unshadowed
  double exposure = 0.6;
  Eigen::Vector3f white_balance = Eigen::Vector3f::Ones();  // per-channel gains
};

// The reference lighting of truth images: a fixed sun, neutral white balance.
ScanLighting reference_lighting();

// Seeded per-scan lighting: sun elevation 20°–65°, any azimuth, exposure
// 0.45–0.8, white balance gains within ±12 %.
ScanLighting random_lighting(std::uint64_t seed);

// The reference sun and sky with random_lighting(seed)'s exposure and white
// balance: scans of one campaign lit so differ by per-channel gains only.
ScanLighting one_sun_lighting(std::uint64_t seed);

// Per-pixel truth, rows × columns, row-major like the scan.
struct ScanTruth {
  std::vector<ObjectId> object_id;  // object under the beam centre; 0 = no return
  std::vector<Eigen::Vector3f>
      normal_scan;                  // unit, scan frame, facing the scanner; zero where no return
  std::vector<float> range_m;       // noise-free range of the beam centre; 0 where no return
  std::vector<std::uint8_t> mixed;  // 1 = mixed pixel (its range is a blend)
};

struct SimulationSettings {
  int threads = 0;  // 0 = all cores; results do not depend on it
};

struct SimulatedScan {
  Scan scan;
  ScanTruth truth;
};

// Scans `scene` from T_world_scan. The scan is spherical: column c looks at
// azimuth −(c + 0.5) · 360° / columns (clockwise from above, so the panorama
// is not mirrored), row r at elevation
// elevation_max − (r + 0.5) · window / rows (row 0 at the top). Every random
// draw is a hash of (seed, pixel), so the result is bit-identical for a seed
// whatever the thread count. Asserts the model is sane (positive sizes,
// min < max) and the scene is built.
SimulatedScan simulate_scan(const Scene& scene, const Eigen::Isometry3d& T_world_scan,
                            const ScannerModel& model, const ScanLighting& lighting,
                            std::uint64_t seed, const SimulationSettings& settings = {});

// Linear radiance → 8-bit sRGB display value, with exposure and white
// balance applied; shared by scans and truth images.
Eigen::Matrix<std::uint8_t, 3, 1> expose(const Eigen::Vector3f& radiance,
                                         const ScanLighting& lighting);

// Linear radiance leaving the surface at `hit` towards the viewer under
// `lighting`: albedo · (sky + sun · max(0, n·s) · visible), where `visible`
// casts a shadow ray when `shadows` is set. `albedo` is the surface's
// (textures.hpp), averaged over the pixel's footprint.
Eigen::Vector3f shade(const Scene& scene, const Hit& hit, const Eigen::Vector3d& point_world,
                      const ScanLighting& lighting, bool shadows, const Eigen::Vector3f& albedo);

// Radius [m] of the disk a beam or pixel of angular size pixel_angle_rad
// covers on a surface at `range_m` whose normal makes cos_incidence with the
// ray (grazing surfaces are clamped at cos 0.1).
double footprint_radius(double range_m, double pixel_angle_rad, double cos_incidence);

}  // namespace scanbench::acquisition::sim
