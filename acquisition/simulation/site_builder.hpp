// Internal to the procedural sites: the recurring parts (terrain, buildings
// with recessed windows and doors, trees, lamp posts, cars, low walls) and the
// scan campaign, so campus_site.cpp and street_site.cpp only hold layouts.
// Not part of the public API.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/scene.hpp"
#include "acquisition/simulation/sites.hpp"

namespace scanbench::acquisition::sim::detail {

// A gently sloped height field: a tilted plane plus a few long, low sine
// waves, so slopes stay within a few per cent everywhere.
struct Terrain {
  struct Wave {
    Eigen::Vector2d wave_vector =
        Eigen::Vector2d::Zero();  // 2π / wavelength along the crest normal [1/m]
    double amplitude_m = 0.0;
    double phase_rad = 0.0;
  };
  double base_z = 0.0;                                 // height at the origin, without waves [m]
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();  // plane slope dz/dx, dz/dy
  std::array<Wave, 3> waves{};

  // Height of the ground [m] at world (x, y) [m].
  double height(const Eigen::Vector2d& xy) const;
};

struct TerrainSettings {
  double min_slope = 0.01;  // rise over run of the plane
  double max_slope = 0.03;
  double slope_azimuth_min_rad = 0.0;  // direction of steepest ascent, drawn uniformly
  double slope_azimuth_max_rad = 6.283185307179586;
  double max_wave_amplitude_m = 0.18;
  double min_wavelength_m = 35.0;
};

Terrain random_terrain(Random& random, const TerrainSettings& settings);

// The materials every site uses, added to the scene in a fixed order.
struct MaterialSet {
  MaterialId grass, asphalt, concrete, paving, brick_red, brick_yellow, plaster_white,
      plaster_ochre, stone, wood, glass, roof, bark, foliage, paint_red, paint_blue, paint_grey,
      metal, rubber, lamp;
};

MaterialSet add_standard_materials(Scene& scene);

// A rectangular building. Sides are numbered counter-clockwise in the
// building frame: 0 faces local −y, 1 local +x, 2 local +y, 3 local −x.
struct BuildingSpec {
  std::string name;
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // world (x, y) [m]
  Eigen::Vector2d size = Eigen::Vector2d(10, 10);    // along local x and y [m]
  double yaw_rad = 0.0;
  int floors = 3;
  double ground_floor_height_m = 3.6;
  double floor_height_m = 3.6;
  MaterialId wall = 0;
  int entrance_side = 0;             // the side with the door (and the sign)
  unsigned windowed_sides = 0b1111;  // bit k set: side k has a window grid
  double window_spacing_m = 2.8;     // centre to centre
  std::string sign_text;             // above the door (campus) or shop window; empty: none
  bool shop_front = false;           // ground floor: shop window + door instead of windows
};

// A building spec with the given placement and defaults for the rest.
BuildingSpec building_at(std::string name, const Eigen::Vector2d& center,
                         const Eigen::Vector2d& size, double yaw_rad, int floors);

struct TreeSpec {
  double trunk_radius_m = 0.25;
  double crown_base_m = 2.8;                // lowest foliage above the ground [m]
  Eigen::Vector2d crown_radii_m{2.5, 2.5};  // horizontal and vertical semi-axes [m]
  int leaf_count = 250;                     // foliage spheres
};

struct GroundSpec {
  Eigen::AlignedBox2d extent;  // world (x, y) [m]; multiple of tile_m on each side
  double cell_m = 1.0;         // triangle grid spacing; divides tile_m
  double tile_m = 10.0;        // one ground object per tile
  std::string name = "ground";  // tiles are named NAME_<row>_<column>
};

// Footprint that scan positions keep clear of: a rectangle rotated by yaw,
// grown by radius (a circle when half_extent is zero).
struct Obstacle {
  Eigen::Vector2d center;
  Eigen::Vector2d half_extent;
  double yaw_rad = 0.0;
  double radius_m = 0.0;
};

class SiteBuilder {
 public:
  SiteBuilder(Scene& scene, const Terrain& terrain, ObjectId site);

  // Height of the ground [m] at world (x, y): everything stands on it.
  double ground_height(const Eigen::Vector2d& xy) const { return terrain_.height(xy); }
  const MaterialSet& materials() const { return materials_; }
  Scene& scene() { return scene_; }

  // Triangle mesh of the terrain, one "ground" object per tile; `surface`
  // picks each triangle's material from its centroid (paths, roads, lawns).
  void add_ground(const GroundSpec& spec,
                  const std::function<MaterialId(const Eigen::Vector2d&)>& surface);
  void add_building(const BuildingSpec& spec);
  void add_tree(const std::string& name, const Eigen::Vector2d& base, const TreeSpec& spec,
                Random& random);
  void add_lamp_post(const std::string& name, const Eigen::Vector2d& base);
  void add_car(const std::string& name, const Eigen::Vector2d& center, double yaw_rad,
               MaterialId paint);
  void add_low_wall(const std::string& name, const Eigen::Vector2d& from,
                    const Eigen::Vector2d& to);

  // Distance [m] from (x, y) to the nearest obstacle footprint (negative inside).
  double clearance(const Eigen::Vector2d& xy) const;

 private:
  struct Facade;
  struct Opening;
  struct FacadeLayout;
  Facade make_facade(const BuildingSpec& spec, int side, double base_z, double floor_z,
                     double top_z) const;
  void add_facade(const BuildingSpec& spec, ObjectId building, const Facade& facade, int side);
  FacadeLayout entrance_layout(const BuildingSpec& spec, const Facade& facade, ObjectId building);
  void add_window_grid(const BuildingSpec& spec, const Facade& facade, ObjectId building,
                       const std::string& prefix, FacadeLayout& layout);
  void add_wall_around(const Facade& facade, const std::vector<Opening>& openings, ObjectId wall,
                       MaterialId material);
  void add_recess(const Facade& facade, const Opening& opening, ObjectId wall, MaterialId material);
  void add_sign(const Facade& facade, ObjectId building, const std::string& name,
                const std::string& text, const Eigen::AlignedBox2d& area);

  Scene& scene_;
  Terrain terrain_;
  ObjectId site_;
  MaterialSet materials_;
  std::vector<Obstacle> obstacles_;
};

// Scan positions along a closed loop: scan i stands about gaps_m[i-1] further
// along the loop than scan i-1 (the last gap repeats for long campaigns),
// jittered and pushed clear of obstacles. Where target_overlaps gives a value
// for that gap, the loop from 0.5 to 3 gaps on is searched for a position
// whose estimated overlap with the previous scan is close to the target, so
// the campaign keeps its overlaps whatever the seed does to the layout.
struct CampaignSettings {
  std::vector<Eigen::Vector2d> loop;    // closed polyline, world (x, y) [m]
  std::vector<double> gaps_m;           // increasing spacing → decreasing overlap
  std::vector<double> target_overlaps;  // per gap, in (0, 1); missing or ≤ 0: the gap as is
  double jitter_m = 0.6;
  double min_clearance_m = 1.6;
  double max_tilt_rad = 0.035;  // ≈ 2°
};

// T_world_scan of `count` scans. `scene` must be built (overlaps are
// estimated by ray casting).
std::vector<Eigen::Isometry3d> plan_scan_poses(const SiteBuilder& builder, const Scene& scene,
                                               const CampaignSettings& settings, int count,
                                               Random& random);

// Builds the scene's BVH (the site is complete), then plans the campaign
// with the scan-placement random stream of the site's seed: the last step of
// every site.
std::vector<Eigen::Isometry3d> finish_site(const SiteBuilder& builder, Scene& scene,
                                           const CampaignSettings& settings, std::uint64_t seed,
                                           int count);

// Share of the surface seen from `a` (2° grid, elevations −45°…45°, up to
// 100 m) that `b` sees too, averaged with the reverse: a coarse overlap of
// two scans from the given optical centres.
double estimate_overlap(const Scene& scene, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// The sites themselves (campus_site.cpp, street_site.cpp, path_site.cpp); make_site()
// dispatches to them.
Site make_campus(std::uint64_t seed, int scan_count);
Site make_street(std::uint64_t seed, int scan_count);
Site make_path(std::uint64_t seed, int scan_count);
int max_path_scans();

}  // namespace scanbench::acquisition::sim::detail
