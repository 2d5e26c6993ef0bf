// Surface appearance of the virtual world: procedural patterns that give the
// scans colour detail worth registering, segmenting and recolouring, and sign
// images with readable lettering.
#pragma once

#include <Eigen/Core>
#include <string>

#include "acquisition/simulation/scene.hpp"

namespace scanbench::acquisition::sim {

// Linear RGB albedo in [0, 1] at the hit: the material's pattern at
// hit.uv_m, averaged over a disk of radius footprint_m [m] on the surface
// (the area one pixel or laser footprint covers; 0 = point sample).
// Deterministic, thread-safe, no allocation.
Eigen::Vector3f surface_albedo(const Scene& scene, const Hit& hit, double footprint_m = 0.0);

// Reflectance at the laser wavelength in [0, 1] at the hit, averaged like the
// albedo: the material's reflectance, modulated by the pattern (mortar joints
// darker than bricks, glass low), so intensity images show the same structure
// as colour.
float surface_reflectance(const Scene& scene, const Hit& hit, double footprint_m = 0.0);

// Both of the above at one hit, from one evaluation of the pattern (each
// alone evaluates it over the footprint's disk: thirteen samples).
struct SurfaceAppearance {
  Eigen::Vector3f albedo = Eigen::Vector3f::Zero();  // linear RGB in [0, 1]
  float reflectance = 0.0f;                          // in [0, 1]
};
SurfaceAppearance surface_appearance(const Scene& scene, const Hit& hit, double footprint_m = 0.0);

// Renders `text` in large capitals (dark letters on a light panel, linear RGB)
// into an image of the given physical size, with about `pixels_per_m` texels
// per metre: a building's name sign or a shop front.
TextureImage make_sign_image(const std::string& text, double width_m, double height_m,
                             double pixels_per_m = 200.0);

}  // namespace scanbench::acquisition::sim
