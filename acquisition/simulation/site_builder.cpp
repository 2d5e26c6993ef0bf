// The recurring small parts of a site: terrain and its mesh, materials,
// trees, lamp posts, cars and low walls. Buildings are in site_building.cpp,
// the scan campaign in site_campaign.cpp.
#include "acquisition/simulation/site_builder.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

namespace scanbench::acquisition::sim::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// World offset of a point given in a frame rotated by yaw.
Vector2d rotated(const Vector2d& local, double yaw_rad) {
  return Eigen::Rotation2Dd(yaw_rad) * local;
}

MaterialId add(Scene& scene, const char* name, Eigen::Vector3f albedo, float reflectance,
               Pattern pattern, float scale_m) {
  return scene.add_material(Material{name, albedo, reflectance, pattern, scale_m, -1});
}

std::string numbered(const std::string& prefix, int row, int col) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "_%02d_%02d", row, col);
  return prefix + buffer;
}

}  // namespace

double Terrain::height(const Vector2d& xy) const {
  double z = base_z + gradient.dot(xy);
  for (const Wave& w : waves) z += w.amplitude_m * std::sin(w.wave_vector.dot(xy) + w.phase_rad);
  return z;
}

Terrain random_terrain(Random& random, const TerrainSettings& s) {
  Terrain t;
  const double slope = random.uniform(s.min_slope, s.max_slope);
  const double azimuth = random.uniform(s.slope_azimuth_min_rad, s.slope_azimuth_max_rad);
  t.gradient = slope * Vector2d(std::cos(azimuth), std::sin(azimuth));
  for (Terrain::Wave& w : t.waves) {
    const double wavelength = random.uniform(s.min_wavelength_m, 2.0 * s.min_wavelength_m);
    const double direction = random.uniform(0.0, 2.0 * std::numbers::pi);
    w.wave_vector =
        2.0 * std::numbers::pi / wavelength * Vector2d(std::cos(direction), std::sin(direction));
    w.amplitude_m = random.uniform(0.3, 1.0) * s.max_wave_amplitude_m / 3.0;
    w.phase_rad = random.uniform(0.0, 2.0 * std::numbers::pi);
  }
  return t;
}

MaterialSet add_standard_materials(Scene& scene) {
  using P = Pattern;
  using C = Eigen::Vector3f;
  MaterialSet m{};
  m.grass = add(scene, "grass", C(0.10f, 0.24f, 0.05f), 0.55f, P::kGrass, 1.5f);
  m.asphalt = add(scene, "asphalt", C(0.09f, 0.09f, 0.095f), 0.15f, P::kAsphalt, 1.0f);
  m.concrete = add(scene, "concrete", C(0.50f, 0.49f, 0.46f), 0.45f, P::kConcrete, 1.5f);
  m.paving = add(scene, "paving", C(0.42f, 0.36f, 0.31f), 0.4f, P::kStone, 0.4f);
  m.brick_red = add(scene, "brick_red", C(0.36f, 0.12f, 0.07f), 0.45f, P::kBrick, 0.24f);
  m.brick_yellow = add(scene, "brick_yellow", C(0.55f, 0.42f, 0.24f), 0.5f, P::kBrick, 0.24f);
  m.plaster_white = add(scene, "plaster_white", C(0.72f, 0.70f, 0.64f), 0.6f, P::kPlaster, 0.8f);
  m.plaster_ochre = add(scene, "plaster_ochre", C(0.62f, 0.45f, 0.24f), 0.55f, P::kPlaster, 0.8f);
  m.stone = add(scene, "stone", C(0.46f, 0.43f, 0.37f), 0.5f, P::kStone, 0.6f);
  m.wood = add(scene, "wood", C(0.26f, 0.14f, 0.07f), 0.4f, P::kWood, 0.5f);
  m.glass = add(scene, "glass", C(0.10f, 0.12f, 0.14f), 0.05f, P::kGlass, 1.0f);
  m.roof = add(scene, "roof", C(0.22f, 0.22f, 0.24f), 0.3f, P::kConcrete, 3.0f);
  m.bark = add(scene, "bark", C(0.20f, 0.14f, 0.09f), 0.4f, P::kBark, 0.12f);
  m.foliage = add(scene, "foliage", C(0.08f, 0.20f, 0.05f), 0.55f, P::kFoliage, 0.3f);
  m.paint_red = add(scene, "paint_red", C(0.50f, 0.04f, 0.03f), 0.5f, P::kPaint, 1.0f);
  m.paint_blue = add(scene, "paint_blue", C(0.05f, 0.10f, 0.40f), 0.45f, P::kPaint, 1.0f);
  m.paint_grey = add(scene, "paint_grey", C(0.45f, 0.46f, 0.47f), 0.55f, P::kPaint, 1.0f);
  m.metal = add(scene, "metal", C(0.16f, 0.17f, 0.18f), 0.5f, P::kMetal, 0.5f);
  m.rubber = add(scene, "rubber", C(0.03f, 0.03f, 0.03f), 0.1f, P::kFlat, 1.0f);
  m.lamp = add(scene, "lamp", C(0.90f, 0.88f, 0.80f), 0.7f, P::kFlat, 1.0f);
  return m;
}

SiteBuilder::SiteBuilder(Scene& scene, const Terrain& terrain, ObjectId site)
    : scene_(scene), terrain_(terrain), site_(site), materials_(add_standard_materials(scene)) {}

void SiteBuilder::add_ground(const GroundSpec& spec,
                             const std::function<MaterialId(const Vector2d&)>& surface) {
  const Vector2d size = spec.extent.sizes();
  const int tile_rows = static_cast<int>(std::lround(size.y() / spec.tile_m));
  const int tile_cols = static_cast<int>(std::lround(size.x() / spec.tile_m));
  const int cells = static_cast<int>(std::lround(spec.tile_m / spec.cell_m));
  const auto vertex = [&](double x, double y) {
    return Vector3d(x, y, ground_height(Vector2d(x, y)));
  };
  for (int tr = 0; tr < tile_rows; ++tr) {
    for (int tc = 0; tc < tile_cols; ++tc) {
      const ObjectId tile = scene_.add_object(numbered(spec.name, tr, tc), site_, "ground");
      const Vector2d corner = spec.extent.min() + spec.tile_m * Vector2d(tc, tr);
      for (int r = 0; r < cells; ++r) {
        for (int c = 0; c < cells; ++c) {
          const double x0 = corner.x() + c * spec.cell_m;
          const double y0 = corner.y() + r * spec.cell_m;
          const double x1 = x0 + spec.cell_m;
          const double y1 = y0 + spec.cell_m;
          const MaterialId material =
              surface(Vector2d(x0 + 0.5 * spec.cell_m, y0 + 0.5 * spec.cell_m));
          scene_.add(Triangle{vertex(x0, y0), vertex(x1, y0), vertex(x1, y1)}, tile, material);
          scene_.add(Triangle{vertex(x0, y0), vertex(x1, y1), vertex(x0, y1)}, tile, material);
        }
      }
    }
  }
}

// Foliage spheres fill an ellipsoid, denser towards its skin like real
// crowns; a smooth lobe pattern makes the outline irregular. Leaves never
// hang below crown_base_m, so scanners under a neighbouring crown stay clear.
void SiteBuilder::add_tree(const std::string& name, const Vector2d& base, const TreeSpec& spec,
                           Random& random) {
  const ObjectId tree = scene_.add_object(name, site_, "tree");
  const ObjectId trunk = scene_.add_object(name + "/trunk", tree, "trunk");
  const ObjectId crown = scene_.add_object(name + "/crown", tree, "crown");
  const double ground = ground_height(base);
  const double rx = spec.crown_radii_m.x();
  const double rz = spec.crown_radii_m.y();
  const double lowest = ground + spec.crown_base_m;
  const Vector3d centre(base.x(), base.y(), lowest + 1.1 * rz);
  scene_.add(Cylinder{Vector3d(base.x(), base.y(), ground - 0.3), spec.trunk_radius_m,
                      centre.z() - ground + 0.3},
             trunk, materials_.bark);
  const double lobe_phase = random.uniform(0.0, 2.0 * std::numbers::pi);
  for (int i = 0; i < spec.leaf_count; ++i) {
    // z, then y, then x (random.hpp).
    const double dz = random.normal();
    const double dy = random.normal();
    Vector3d d(random.normal(), dy, dz);
    d /= std::max(d.norm(), 1e-9);
    const double azimuth = std::atan2(d.y(), d.x());
    const double lobe = 1.0 + 0.15 * std::sin(3.0 * azimuth + lobe_phase) * std::cos(2.5 * d.z());
    const double r = std::pow(random.uniform(), 0.25) * lobe;
    const double radius = random.uniform(0.15, 0.4);
    Vector3d p = centre + Vector3d(rx * d.x() * r, rx * d.y() * r, rz * d.z() * r);
    if (p.z() - radius < lowest) p.z() = 2.0 * centre.z() - p.z();  // mirror into the upper half
    scene_.add(Sphere{p, radius}, crown, materials_.foliage);
  }
  obstacles_.push_back({base, Vector2d::Zero(), 0.0, spec.trunk_radius_m});
}

void SiteBuilder::add_lamp_post(const std::string& name, const Vector2d& base) {
  const ObjectId post = scene_.add_object(name, site_, "lamp_post");
  const double ground = ground_height(base);
  constexpr double kHeight = 4.5;
  scene_.add(Cylinder{Vector3d(base.x(), base.y(), ground - 0.3), 0.07, kHeight + 0.3}, post,
             materials_.metal);
  scene_.add(Cylinder{Vector3d(base.x(), base.y(), ground - 0.3), 0.14, 0.8}, post,
             materials_.metal);  // the thicker foot
  const Vector3d lamp(base.x(), base.y(), ground + kHeight + 0.2);
  scene_.add(Sphere{lamp, 0.22}, post, materials_.lamp);
  scene_.add(Box{lamp + Vector3d(0, 0, 0.25), Vector3d(0.3, 0.3, 0.04), 0.0}, post,
             materials_.metal);  // the cap
  obstacles_.push_back({base, Vector2d::Zero(), 0.0, 0.3});
}

// A car of boxes: body, glazed cabin and four wheels (cylinders in the scene
// are vertical, so wheels are short boxes, which look the same to a scanner
// from the side at a distance).
void SiteBuilder::add_car(const std::string& name, const Vector2d& center, double yaw_rad,
                          MaterialId paint) {
  const ObjectId car = scene_.add_object(name, site_, "car");
  const double ground = ground_height(center);
  const auto at = [&](double along, double across, double up) {
    const Vector2d xy = center + rotated(Vector2d(along, across), yaw_rad);
    return Vector3d(xy.x(), xy.y(), ground + up);
  };
  scene_.add(Box{at(0.0, 0.0, 0.7), Vector3d(2.2, 0.88, 0.38), yaw_rad}, car, paint);
  scene_.add(Box{at(-0.25, 0.0, 1.33), Vector3d(1.2, 0.78, 0.26), yaw_rad}, car, materials_.glass);
  scene_.add(Box{at(-0.25, 0.0, 1.62), Vector3d(1.15, 0.74, 0.04), yaw_rad}, car, paint);
  for (const double along : {-1.4, 1.4}) {
    for (const double across : {-0.8, 0.8}) {
      scene_.add(Box{at(along, across, 0.3), Vector3d(0.33, 0.12, 0.34), yaw_rad}, car,
                 materials_.rubber);
    }
  }
  obstacles_.push_back({center, Vector2d(2.2, 0.92), yaw_rad, 0.0});
}

// Stone segments of at most 3 m so the 0.8 m high wall follows the slope;
// each reaches 0.3 m below the lowest ground under it.
void SiteBuilder::add_low_wall(const std::string& name, const Vector2d& from, const Vector2d& to) {
  const ObjectId wall = scene_.add_object(name, site_, "low_wall");
  const Vector2d span = to - from;
  const int segments = std::max(1, static_cast<int>(std::ceil(span.norm() / 3.0)));
  const double yaw = std::atan2(span.y(), span.x());
  const double half_length = 0.5 * span.norm() / segments;
  for (int i = 0; i < segments; ++i) {
    const Vector2d a = from + span * (static_cast<double>(i) / segments);
    const Vector2d b = from + span * (static_cast<double>(i + 1) / segments);
    const Vector2d mid = 0.5 * (a + b);
    const double top = ground_height(mid) + 0.8;
    const double bottom = std::min(ground_height(a), ground_height(b)) - 0.3;
    scene_.add(Box{Vector3d(mid.x(), mid.y(), 0.5 * (top + bottom)),
                   Vector3d(half_length, 0.2, 0.5 * (top - bottom)), yaw},
               wall, materials_.stone);
  }
  obstacles_.push_back({0.5 * (from + to), Vector2d(0.5 * span.norm(), 0.2), yaw, 0.0});
}

double SiteBuilder::clearance(const Vector2d& xy) const {
  double nearest = std::numeric_limits<double>::infinity();
  for (const Obstacle& o : obstacles_) {
    const Vector2d local = rotated(xy - o.center, -o.yaw_rad).cwiseAbs();
    const Vector2d outside = (local - o.half_extent).cwiseMax(0.0);
    const double inside = std::min(0.0, (local - o.half_extent).maxCoeff());
    nearest = std::min(nearest, outside.norm() + inside - o.radius_m);
  }
  return nearest;
}

}  // namespace scanbench::acquisition::sim::detail
