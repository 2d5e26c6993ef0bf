// The "campus" site: a lawn quad framed by three named buildings, crossed by
// concrete paths, with trees, lamp posts, a low stone wall and a road with a
// parked car to the south. The layout is fixed; the seed moves, turns and
// resizes things a little and draws the terrain, the trees and the campaign.
#include <algorithm>
#include <cstdio>
#include <numbers>

#include "acquisition/simulation/site_builder.hpp"

namespace scanbench::acquisition::sim::detail {
namespace {

using Eigen::Vector2d;

// Distance from p to the segment a–b [m].
double segment_distance(const Vector2d& p, const Vector2d& a, const Vector2d& b) {
  const Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Ground cover: a road in the south, a paved forecourt before north hall,
// concrete paths between the doors, lawn elsewhere.
MaterialId campus_surface(const MaterialSet& m, const Vector2d& p) {
  if (p.y() > -36.0 && p.y() < -29.0) return m.asphalt;
  if (p.x() > -8.0 && p.x() < 8.0 && p.y() > 12.0 && p.y() < 19.5) return m.paving;
  const Vector2d paths[][2] = {
      {{-25.0, -2.0}, {0.0, -2.0}}, {{0.0, -2.0}, {21.0, -12.0}}, {{0.0, 19.0}, {0.0, -29.0}}};
  for (const auto& path : paths) {
    if (segment_distance(p, path[0], path[1]) < 1.5) return m.concrete;
  }
  return m.grass;
}

void add_buildings(SiteBuilder& b, Random& random) {
  const MaterialSet& m = b.materials();
  const auto jitter = [&](double size) { return random.uniform(-size, size); };
  BuildingSpec north = building_at("north_hall", Vector2d(jitter(1.0), 26.0 + jitter(0.5)),
                                   Vector2d(40.0 + jitter(2.0), 14.0), jitter(0.04), 4);
  north.wall = m.brick_red;
  north.entrance_side = 0;
  north.sign_text = "NORTHROP HALL";
  BuildingSpec library =
      building_at("walter_library", Vector2d(-34.0 + jitter(1.0), -2.0 + jitter(1.0)),
                  Vector2d(18.0, 32.0 + jitter(2.0)), 0.05 + jitter(0.03), 3);
  library.wall = m.stone;
  library.entrance_side = 1;
  library.sign_text = "WALTER LIBRARY";
  BuildingSpec keller = building_at("keller_hall", Vector2d(32.0 + jitter(1.0), -8.0 + jitter(1.0)),
                                    Vector2d(24.0 + jitter(1.5), 16.0), 0.35 + jitter(0.05), 5);
  keller.wall = m.plaster_white;
  keller.entrance_side = 3;
  keller.sign_text = "KELLER HALL";
  for (const BuildingSpec& spec : {north, library, keller}) b.add_building(spec);
}

void add_trees(SiteBuilder& b, std::uint64_t seed) {
  const Vector2d bases[] = {{-14, 9}, {13, 10},   {-12, -13}, {10, -19}, {-52, 28},
                            {48, 26}, {-50, -40}, {40, -44},  {-6, 42},  {22, 40}};
  int index = 0;
  for (const Vector2d& base : bases) {
    Random random(hash_combine(seed, 0x7472656500ull + static_cast<std::uint64_t>(index)));
    TreeSpec spec;
    spec.trunk_radius_m = random.uniform(0.15, 0.3);
    spec.crown_base_m = random.uniform(2.6, 3.4);
    const double crown_ry = random.uniform(2.2, 3.2);  // drawn first (random.hpp)
    spec.crown_radii_m = Vector2d(random.uniform(2.0, 3.2), crown_ry);
    spec.leaf_count = random.integer(150, 400);
    char name[32];
    std::snprintf(name, sizeof name, "tree_%02d", ++index);
    const double jitter_y = random.uniform(-1.0, 1.0);  // drawn first (random.hpp)
    const Vector2d jitter(random.uniform(-1.0, 1.0), jitter_y);
    b.add_tree(name, base + jitter, spec, random);
  }
}

void add_street_furniture(SiteBuilder& b, Random& random) {
  const Vector2d posts[] = {{2.2, 8},    {-2.2, -12},  {-12, -0.2},
                            {-20, -3.8}, {-20, -27.5}, {20, -27.5}};
  int index = 0;
  for (const Vector2d& base : posts) {
    char name[24];
    std::snprintf(name, sizeof name, "lamp_post_%02d", ++index);
    b.add_lamp_post(name, base);
  }
  const double car_yaw = random.uniform(-0.05, 0.05);  // drawn first (random.hpp)
  b.add_car("car_01", Vector2d(8.0 + random.uniform(-2.0, 2.0), -31.0), car_yaw,
            b.materials().paint_red);
  b.add_low_wall("low_wall_01", Vector2d(-28.0, -24.0),
                 Vector2d(-2.5, -24.0 + random.uniform(-0.5, 0.5)));
}

}  // namespace

Site make_campus(std::uint64_t seed, int scan_count) {
  Site site{"campus", Scene{}, {}};
  Scene& scene = site.scene;
  const ObjectId root = scene.add_object("campus", 0, "site");
  Random layout(hash_combine(seed, 0x63616d707573ull));
  SiteBuilder builder(scene, random_terrain(layout, TerrainSettings{}), root);
  add_buildings(builder, layout);
  add_trees(builder, seed);
  const MaterialSet materials = builder.materials();
  builder.add_ground(
      GroundSpec{Eigen::AlignedBox2d(Vector2d(-70, -50), Vector2d(70, 50)), 1.25, 10.0},
      [&](const Vector2d& p) { return campus_surface(materials, p); });
  add_street_furniture(builder, layout);
  CampaignSettings campaign;
  // Three scans in the quad, the fourth in the gap east of north hall or
  // behind it, where the building hides most of the quad (≈ 30 % overlap);
  // longer campaigns continue round the back of north hall and the library.
  campaign.loop = {{-10, 4}, {-4, 4}, {16, 12}, {26, 30}, {24, 42}, {-40, 42}, {-48, 20}};
  for (std::size_t i = 0; i < 3; ++i)
    campaign.gaps_m.push_back((campaign.loop[i + 1] - campaign.loop[i]).norm());
  campaign.target_overlaps = {0.0, 0.0, 0.32};  // only the last gap is searched
  site.scan_poses = finish_site(builder, scene, campaign, seed, scan_count);
  return site;
}

}  // namespace scanbench::acquisition::sim::detail
