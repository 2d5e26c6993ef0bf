// Buildings: four façades with real openings. Each façade is tiled with wall
// quads around its window and door openings; every opening gets four reveal
// quads and a pane set back into the wall, so the scanner sees the recess
// (and the mixed pixels along its edges) rather than a painted-on window.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>

#include "acquisition/simulation/site_builder.hpp"
#include "acquisition/simulation/textures.hpp"

namespace scanbench::acquisition::sim::detail {

using Eigen::AlignedBox2d;
using Eigen::Vector2d;
using Eigen::Vector3d;

// One side of a building in façade coordinates (u, v) [m]: u runs to the
// right as seen from outside, v up from the wall's base below the terrain.
struct SiteBuilder::Facade {
  Vector3d origin;  // world position of (u, v) = (0, 0)
  Vector3d along;   // unit, +u
  Vector3d normal;  // unit, outward
  double width_m = 0.0;
  double height_m = 0.0;
  double floor_v = 0.0;  // ground-floor level
  Vector2d lattice;      // repeat of the wall pattern: openings snap to it

  Vector3d at(double u, double v) const { return origin + along * u + Vector3d::UnitZ() * v; }
};

struct SiteBuilder::Opening {
  AlignedBox2d box;  // (u, v) extent on the façade [m]
  double depth_m = 0.0;
  ObjectId object = 0;
  MaterialId material = 0;
};

struct SiteBuilder::FacadeLayout {
  std::vector<Opening> openings;
  std::optional<AlignedBox2d> sign;                         // (u, v) extent of the sign panel
  AlignedBox2d keep_clear;  // no windows here; empty by default
};

namespace {

constexpr double kWindowWidth = 1.2;
constexpr double kWindowHeight = 1.5;
constexpr double kSill = 0.9;
constexpr double kWindowDepth = 0.15;
constexpr double kDoorDepth = 0.3;

// Wall quads each start their texture at their own corner; snapping every
// opening edge to the pattern's repeat keeps brick courses continuous.
Vector2d pattern_lattice(const Material& m) {
  if (m.pattern == Pattern::kBrick) return {m.texture_scale_m, 2.0 * m.texture_scale_m / 3.0};
  if (m.pattern == Pattern::kStone) return {m.texture_scale_m, m.texture_scale_m};
  return {0.05, 0.05};
}

double snap(double x, double step) {
  return std::round(x / step) * step;
}
double snap_up(double x, double step) {
  return std::ceil(x / step - 1e-9) * step;
}

AlignedBox2d snapped(const AlignedBox2d& box, const Vector2d& lattice) {
  return {Vector2d(snap(box.min().x(), lattice.x()), snap(box.min().y(), lattice.y())),
          Vector2d(snap(box.max().x(), lattice.x()), snap(box.max().y(), lattice.y()))};
}

std::string compass(const Vector3d& normal) {
  static const char* const kNames[] = {"east", "north", "west", "south"};
  const double quarter = std::atan2(normal.y(), normal.x()) / (0.5 * std::numbers::pi);
  const long k = ((std::lround(quarter) % 4) + 4) % 4;
  return kNames[k];
}

// The lowest and highest ground under a rotated rectangle, sampled on a grid.
std::pair<double, double> ground_range(const SiteBuilder& b, const BuildingSpec& spec) {
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; j <= 8; ++j) {
      const Vector2d local = spec.size.cwiseProduct(Vector2d(i / 8.0 - 0.5, j / 8.0 - 0.5));
      const double z = b.ground_height(spec.center + Eigen::Rotation2Dd(spec.yaw_rad) * local);
      low = std::min(low, z);
      high = std::max(high, z);
    }
  }
  return {low, high};
}

}  // namespace

BuildingSpec building_at(std::string name, const Vector2d& center, const Vector2d& size,
                         double yaw_rad, int floors) {
  BuildingSpec spec;
  spec.name = std::move(name);
  spec.center = center;
  spec.size = size;
  spec.yaw_rad = yaw_rad;
  spec.floors = floors;
  return spec;
}

// The building stands on a plinth level with the highest ground under it;
// its walls reach 0.5 m below the lowest ground so no gap shows on a slope.
void SiteBuilder::add_building(const BuildingSpec& spec) {
  assert(spec.floors >= 1 && spec.entrance_side >= 0 && spec.entrance_side < 4 &&
         "building needs a floor and a valid entrance side");
  const ObjectId building = scene_.add_object(spec.name, site_, "building");
  const auto [low, high] = ground_range(*this, spec);
  const double base_z = low - 0.5;
  const double floor_z = high + 0.05;
  const double top_z =
      floor_z + spec.ground_floor_height_m + (spec.floors - 1) * spec.floor_height_m + 0.6;
  for (int side = 0; side < 4; ++side) {
    add_facade(spec, building, make_facade(spec, side, base_z, floor_z, top_z), side);
  }
  const ObjectId roof = scene_.add_object(spec.name + "/roof", building, "roof");
  constexpr double kEave = 0.25;  // cornice overhang [m]
  scene_.add(
      Box{Vector3d(spec.center.x(), spec.center.y(), top_z + 0.175),
          Vector3d(0.5 * spec.size.x() + kEave, 0.5 * spec.size.y() + kEave, 0.175), spec.yaw_rad},
      roof, materials_.roof);
  obstacles_.push_back({spec.center, 0.5 * spec.size, spec.yaw_rad, 0.0});
}

SiteBuilder::Facade SiteBuilder::make_facade(const BuildingSpec& spec, int side, double base_z,
                                             double floor_z, double top_z) const {
  const Vector2d half = 0.5 * spec.size;
  const std::array<Vector2d, 4> corners = {
      Vector2d(-half.x(), -half.y()), Vector2d(half.x(), -half.y()), Vector2d(half.x(), half.y()),
      Vector2d(-half.x(), half.y())};
  const Eigen::Rotation2Dd yaw(spec.yaw_rad);
  const Vector2d start = spec.center + yaw * corners[static_cast<std::size_t>(side)];
  const Vector2d edge = yaw * (corners[static_cast<std::size_t>((side + 1) % 4)] -
                               corners[static_cast<std::size_t>(side)]);
  Facade f;
  f.origin = Vector3d(start.x(), start.y(), base_z);
  f.along = Vector3d(edge.x(), edge.y(), 0.0).normalized();
  f.normal = f.along.cross(Vector3d::UnitZ());  // counter-clockwise corners: outward
  f.width_m = edge.norm();
  f.height_m = top_z - base_z;
  f.floor_v = floor_z - base_z;
  f.lattice = pattern_lattice(scene_.materials()[spec.wall]);
  return f;
}

void SiteBuilder::add_facade(const BuildingSpec& spec, ObjectId building, const Facade& facade,
                             int side) {
  const std::string prefix = spec.name + "/";
  const std::string direction = compass(facade.normal);
  const ObjectId wall = scene_.add_object(prefix + "wall_" + direction, building, "wall");
  FacadeLayout layout;
  if (side == spec.entrance_side) layout = entrance_layout(spec, facade, building);
  if ((spec.windowed_sides >> side) & 1u) {
    add_window_grid(spec, facade, building, prefix + "window_" + direction, layout);
  }
  add_wall_around(facade, layout.openings, wall, spec.wall);
  for (const Opening& opening : layout.openings) add_recess(facade, opening, wall, spec.wall);
  if (layout.sign && !spec.sign_text.empty()) {
    add_sign(facade, building, prefix + "sign", spec.sign_text, *layout.sign);
  }
}

// Campus: a double door in the middle, the name sign above it. Shop front:
// a door near the right end, a large shop window left of it, the shop's sign
// above the window.
SiteBuilder::FacadeLayout SiteBuilder::entrance_layout(const BuildingSpec& spec, const Facade& f,
                                                       ObjectId building) {
  FacadeLayout layout;
  const ObjectId door = scene_.add_object(spec.name + "/door", building, "door");
  const double door_u = spec.shop_front ? f.width_m - 2.2 : 0.5 * f.width_m;
  const double door_half = spec.shop_front ? 0.6 : 0.8;
  const double bottom = snap_up(f.floor_v, f.lattice.y());
  const AlignedBox2d door_box(
      Vector2d(snap(door_u - door_half, f.lattice.x()), bottom),
      Vector2d(snap(door_u + door_half, f.lattice.x()), snap(bottom + 2.4, f.lattice.y())));
  layout.openings.push_back({door_box, kDoorDepth, door, materials_.wood});
  layout.keep_clear =
      AlignedBox2d(door_box.min() - Vector2d(0.6, 1.0), door_box.max() + Vector2d(0.6, 0.3));
  if (!spec.shop_front) {
    const double half_width = 0.5 * std::min(5.0, f.width_m - 1.0);
    const double sign_bottom = door_box.max().y() + 0.35;
    layout.sign = AlignedBox2d(Vector2d(door_u - half_width, sign_bottom),
                               Vector2d(door_u + half_width, sign_bottom + 0.8));
    return layout;
  }
  const ObjectId shop = scene_.add_object(spec.name + "/shop_window", building, "window");
  const AlignedBox2d shop_box =
      snapped(AlignedBox2d(Vector2d(1.0, f.floor_v + 0.5),
                           Vector2d(door_box.min().x() - 0.8, f.floor_v + 3.0)),
              f.lattice);
  layout.openings.push_back({shop_box, kWindowDepth, shop, materials_.glass});
  layout.keep_clear =
      AlignedBox2d(Vector2d(0.0, 0.0), Vector2d(f.width_m, f.floor_v + spec.ground_floor_height_m));
  const double sign_right = std::min(shop_box.max().x(), shop_box.min().x() + 6.0);
  layout.sign = AlignedBox2d(Vector2d(shop_box.min().x(), f.floor_v + 3.2),
                             Vector2d(sign_right, f.floor_v + 4.0));
  return layout;
}

// A regular grid, one window per floor and bay, centred on the façade; the
// same spacing on every building is what makes a street repetitive.
void SiteBuilder::add_window_grid(const BuildingSpec& spec, const Facade& f, ObjectId building,
                                  const std::string& prefix, FacadeLayout& layout) {
  const int bays = static_cast<int>(std::floor((f.width_m - 2.0) / spec.window_spacing_m)) + 1;
  for (int floor = 0; floor < spec.floors; ++floor) {
    const double level =
        f.floor_v +
        (floor == 0 ? 0.0 : spec.ground_floor_height_m + (floor - 1) * spec.floor_height_m);
    for (int bay = 0; bay < bays; ++bay) {
      const double u = 0.5 * f.width_m + (bay - 0.5 * (bays - 1)) * spec.window_spacing_m;
      const AlignedBox2d box =
          snapped(AlignedBox2d(Vector2d(u - 0.5 * kWindowWidth, level + kSill),
                               Vector2d(u + 0.5 * kWindowWidth, level + kSill + kWindowHeight)),
                  f.lattice);
      const bool inside = box.min().x() > 0.3 && box.max().x() < f.width_m - 0.3 &&
                          box.max().y() < f.height_m - 0.3 && !box.isEmpty();
      if (!inside || layout.keep_clear.intersects(box)) continue;
      char suffix[32];
      std::snprintf(suffix, sizeof suffix, "_%d_%02d", floor, bay);
      const ObjectId window = scene_.add_object(prefix + suffix, building, "window");
      layout.openings.push_back({box, kWindowDepth, window, materials_.glass});
    }
  }
}

// Cuts the façade into horizontal bands at every opening edge; within a band
// the wall is the intervals between the openings that span it.
void SiteBuilder::add_wall_around(const Facade& f, const std::vector<Opening>& openings,
                                  ObjectId wall, MaterialId material) {
  std::vector<double> breaks = {0.0, f.height_m};
  for (const Opening& o : openings) {
    breaks.push_back(o.box.min().y());
    breaks.push_back(o.box.max().y());
  }
  std::sort(breaks.begin(), breaks.end());
  breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
  for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
    const double v0 = breaks[b];
    const double v1 = breaks[b + 1];
    std::vector<std::pair<double, double>> holes;
    for (const Opening& o : openings) {
      if (o.box.min().y() <= v0 && o.box.max().y() >= v1) {
        holes.emplace_back(o.box.min().x(), o.box.max().x());
      }
    }
    std::sort(holes.begin(), holes.end());
    holes.emplace_back(f.width_m, f.width_m);
    double u = 0.0;
    for (const auto& [u0, u1] : holes) {
      if (u0 - u > 1e-6) {
        scene_.add(Quad{f.at(u, v0), f.along * (u0 - u), Vector3d::UnitZ() * (v1 - v0)}, wall,
                   material);
      }
      u = std::max(u, u1);
    }
  }
}

// Reveals (sill, lintel, jambs) in the wall's material, then the pane or
// door leaf at the back of the recess, textured like the façade (u right).
void SiteBuilder::add_recess(const Facade& f, const Opening& o, ObjectId wall,
                             MaterialId material) {
  const Vector2d lo = o.box.min();
  const Vector2d hi = o.box.max();
  const Vector3d inward = -f.normal * o.depth_m;
  const Vector3d across = f.along * (hi.x() - lo.x());
  const Vector3d up = Vector3d::UnitZ() * (hi.y() - lo.y());
  scene_.add(Quad{f.at(lo.x(), lo.y()), across, inward}, wall, material);
  scene_.add(Quad{f.at(lo.x(), hi.y()), across, inward}, wall, material);
  scene_.add(Quad{f.at(lo.x(), lo.y()), inward, up}, wall, material);
  scene_.add(Quad{f.at(hi.x(), lo.y()), inward, up}, wall, material);
  scene_.add(Quad{f.at(lo.x(), lo.y()) + inward, across, up}, o.object, o.material);
}

// A panel 6 cm proud of the wall with the text rendered into its texture.
void SiteBuilder::add_sign(const Facade& f, ObjectId building, const std::string& name,
                           const std::string& text, const AlignedBox2d& area) {
  const ObjectId sign = scene_.add_object(name, building, "sign");
  const Vector2d size = area.sizes();
  const int image = scene_.add_image(make_sign_image(text, size.x(), size.y()));
  const MaterialId material = scene_.add_material(
      Material{name, Eigen::Vector3f(0.8f, 0.8f, 0.78f), 0.6f, Pattern::kImage, 1.0f, image});
  scene_.add(Quad{f.at(area.min().x(), area.min().y()) + 0.06 * f.normal, f.along * size.x(),
                  Vector3d::UnitZ() * size.y()},
             sign, material);
}

}  // namespace scanbench::acquisition::sim::detail
