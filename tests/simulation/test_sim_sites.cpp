#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "acquisition/simulation/scene.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/textures.hpp"

namespace scanbench::acquisition::sim {
namespace {

using Eigen::Vector3d;

// Every number that defines a primitive, so two scenes compare exactly.
std::vector<double> flatten(const Primitive& p) {
  std::vector<double> v = {static_cast<double>(p.shape.index()), double(p.object),
                           double(p.material)};
  const auto put = [&](const Vector3d& x) { v.insert(v.end(), x.data(), x.data() + 3); };
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Quad>) {
          put(s.origin);
          put(s.edge_u);
          put(s.edge_v);
        }
        if constexpr (std::is_same_v<T, Box>) {
          put(s.center);
          put(s.half_extent);
          v.push_back(s.yaw_rad);
        }
        if constexpr (std::is_same_v<T, Cylinder>) {
          put(s.base_center);
          v.push_back(s.radius);
          v.push_back(s.height);
        }
        if constexpr (std::is_same_v<T, Sphere>) {
          put(s.center);
          v.push_back(s.radius);
        }
        if constexpr (std::is_same_v<T, Triangle>) {
          put(s.a);
          put(s.b);
          put(s.c);
        }
      },
      p.shape);
  return v;
}

void expect_identical(const Site& a, const Site& b) {
  ASSERT_EQ(a.scene.primitives().size(), b.scene.primitives().size());
  for (std::size_t i = 0; i < a.scene.primitives().size(); ++i) {
    ASSERT_EQ(flatten(a.scene.primitives()[i]), flatten(b.scene.primitives()[i]))
        << "primitive " << i;
  }
  ASSERT_EQ(a.scene.objects().size(), b.scene.objects().size());
  for (std::size_t i = 0; i < a.scene.objects().size(); ++i) {
    const ObjectInfo& x = a.scene.objects()[i];
    const ObjectInfo& y = b.scene.objects()[i];
    EXPECT_TRUE(x.id == y.id && x.name == y.name && x.parent == y.parent && x.kind == y.kind)
        << x.name;
  }
  ASSERT_EQ(a.scene.materials().size(), b.scene.materials().size());
  for (std::size_t i = 0; i < a.scene.materials().size(); ++i) {
    const Material& x = a.scene.materials()[i];
    const Material& y = b.scene.materials()[i];
    EXPECT_TRUE(x.name == y.name && x.albedo == y.albedo && x.reflectance == y.reflectance &&
                x.pattern == y.pattern && x.texture_scale_m == y.texture_scale_m &&
                x.image == y.image);
  }
  ASSERT_EQ(a.scene.images().size(), b.scene.images().size());
  for (std::size_t i = 0; i < a.scene.images().size(); ++i) {
    EXPECT_TRUE(a.scene.images()[i].rgb == b.scene.images()[i].rgb);
  }
  ASSERT_EQ(a.scan_poses.size(), b.scan_poses.size());
  for (std::size_t i = 0; i < a.scan_poses.size(); ++i) {
    EXPECT_TRUE(a.scan_poses[i].matrix() == b.scan_poses[i].matrix()) << "pose " << i;
  }
}

std::vector<ObjectId> children(const Scene& scene, ObjectId parent, const std::string& kind) {
  std::vector<ObjectId> ids;
  for (const ObjectInfo& o : scene.objects()) {
    if (o.parent == parent && o.kind == kind) ids.push_back(o.id);
  }
  return ids;
}

std::map<ObjectId, int> primitive_counts(const Scene& scene) {
  std::map<ObjectId, int> counts;
  for (const Primitive& p : scene.primitives()) ++counts[p.object];
  return counts;
}

Vector3d direction(double azimuth_deg, double elevation_deg) {
  const double az = azimuth_deg * std::numbers::pi / 180.0;
  const double el = elevation_deg * std::numbers::pi / 180.0;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

// Fraction of the surface points scanned from `from` (1° grid, elevations
// −45° … 44°, up to 100 m) that `to` also sees: in range, from the front and
// with a clear line of sight.
double seen_fraction(const Scene& scene, const Vector3d& from, const Vector3d& to) {
  constexpr double kRange = 100.0;
  int hits = 0;
  int shared = 0;
  for (int el = -45; el < 45; ++el) {
    for (int az = 0; az < 360; ++az) {
      const auto hit = scene.intersect({from, direction(az, el)}, 0.1, kRange);
      if (!hit) continue;
      ++hits;
      const Vector3d point = from + hit->distance_m * direction(az, el);
      const Vector3d to_other = to - point;
      const double distance = to_other.norm();
      if (distance > kRange || hit->normal.dot(to_other) < 0.02 * distance) continue;
      const auto blocker = scene.intersect({to, -to_other / distance}, 0.1, distance - 0.05);
      if (!blocker) ++shared;
    }
  }
  return hits == 0 ? 0.0 : static_cast<double>(shared) / hits;
}

// Symmetric overlap of two scans: the mean of both one-way fractions.
double overlap(const Site& site, std::size_t i, std::size_t j) {
  const Vector3d a = site.scan_poses[i].translation();
  const Vector3d b = site.scan_poses[j].translation();
  return 0.5 * (seen_fraction(site.scene, a, b) + seen_fraction(site.scene, b, a));
}

std::vector<double> consecutive_overlaps(const Site& site, const char* label) {
  std::vector<double> overlaps;
  for (std::size_t i = 0; i + 1 < site.scan_poses.size(); ++i) {
    overlaps.push_back(overlap(site, i, i + 1));
    std::cout << label << " overlap scan " << i << "–" << i + 1 << ": " << overlaps.back() << "\n";
    ::testing::Test::RecordProperty(std::string(label) + "_overlap_" + std::to_string(i),
                                    std::to_string(overlaps.back()));
  }
  return overlaps;
}

class SimSitesEachSite : public ::testing::TestWithParam<std::string> {};

TEST(SimSites, NamesAreCampusStreetAndPath) {
  EXPECT_EQ(site_names(), (std::vector<std::string>{"campus", "street", "path"}));
  EXPECT_EQ(max_scan_count("campus"), 64);
  EXPECT_EQ(max_scan_count("path"), 512);
}

TEST_P(SimSitesEachSite, SameSeedGivesIdenticalSite) {
  const Site a = make_site(GetParam(), 42);
  const Site b = make_site(GetParam(), 42);
  EXPECT_EQ(a.name, GetParam());
  expect_identical(a, b);
}

TEST_P(SimSitesEachSite, DifferentSeedsGiveDifferentSites) {
  const Site a = make_site(GetParam(), 1);
  const Site b = make_site(GetParam(), 2);
  EXPECT_FALSE(a.scan_poses[0].matrix() == b.scan_poses[0].matrix());
  const std::size_t n = std::min(a.scene.primitives().size(), b.scene.primitives().size());
  int differing = 0;
  for (std::size_t i = 0; i < n; ++i) {
    differing += flatten(a.scene.primitives()[i]) != flatten(b.scene.primitives()[i]);
  }
  EXPECT_GT(differing, static_cast<int>(n / 2));
}

TEST_P(SimSitesEachSite, HierarchyIsConsistentAndWithinBudget) {
  const Site site = make_site(GetParam(), 7);
  const Scene& scene = site.scene;
  std::cout << GetParam() << ": " << scene.primitives().size() << " primitives, "
            << scene.objects().size() << " objects\n";
  EXPECT_LT(scene.primitives().size(), 60000u);
  ASSERT_FALSE(scene.objects().empty());
  EXPECT_EQ(scene.objects()[0].kind, "site");
  EXPECT_EQ(scene.objects()[0].parent, 0);
  std::set<std::string> names;
  const auto counts = primitive_counts(scene);
  for (std::size_t i = 0; i < scene.objects().size(); ++i) {
    const ObjectInfo& o = scene.objects()[i];
    EXPECT_EQ(o.id, i + 1);
    EXPECT_TRUE(names.insert(o.name).second) << "duplicate name " << o.name;
    if (i > 0) {
      EXPECT_TRUE(o.parent >= 1 && o.parent < o.id) << o.name;
    }
    const bool group = o.kind == "site" || o.kind == "building" || o.kind == "tree";
    EXPECT_EQ(counts.count(o.id) == 0, group) << o.name << " (" << o.kind << ")";
  }
}

// Every building has walls, a door, windows, a roof and a sign whose material
// is an image; every tree a trunk and a crown of many small spheres.
void expect_complete(const Scene& scene, int min_buildings, int min_trees) {
  const auto buildings = children(scene, 1, "building");
  EXPECT_GE(static_cast<int>(buildings.size()), min_buildings);
  std::set<ObjectId> signs;
  for (const ObjectId b : buildings) {
    EXPECT_GE(children(scene, b, "wall").size(), 4u) << scene.object(b).name;
    EXPECT_EQ(children(scene, b, "door").size(), 1u) << scene.object(b).name;
    EXPECT_GE(children(scene, b, "window").size(), 1u) << scene.object(b).name;
    EXPECT_EQ(children(scene, b, "roof").size(), 1u) << scene.object(b).name;
    for (const ObjectId s : children(scene, b, "sign")) signs.insert(s);
  }
  EXPECT_EQ(signs.size(), buildings.size());
  for (const Primitive& p : scene.primitives()) {
    if (signs.count(p.object)) {
      EXPECT_EQ(scene.materials()[p.material].pattern, Pattern::kImage);
    }
  }
  const auto trees = children(scene, 1, "tree");
  EXPECT_GE(static_cast<int>(trees.size()), min_trees);
  const auto counts = primitive_counts(scene);
  for (const ObjectId t : trees) {
    ASSERT_EQ(children(scene, t, "trunk").size(), 1u);
    ASSERT_EQ(children(scene, t, "crown").size(), 1u);
    EXPECT_GE(counts.at(children(scene, t, "crown")[0]), 150);
  }
  for (const char* kind : {"lamp_post", "car", "ground"}) {
    EXPECT_FALSE(children(scene, 1, kind).empty()) << kind;
  }
}

TEST(SimSites, CampusHasAllRequiredParts) {
  const Site site = make_site("campus", 3);
  expect_complete(site.scene, 3, 6);
  EXPECT_EQ(children(site.scene, 1, "low_wall").size(), 1u);
}

TEST(SimSites, StreetHasAllRequiredParts) {
  const Site site = make_site("street", 3);
  expect_complete(site.scene, 16, 3);
}

TEST(SimSites, PathHasAllRequiredPartsOnEveryLeg) {
  const Site site = make_site("path", 3, 12);  // three legs
  expect_complete(site.scene, 24, 3);
  EXPECT_EQ(children(site.scene, 1, "car").size(), 6u);
}

// The path's point: however long the campaign, a scan overlaps only the
// scans of its own leg and the next ones, so the overlap graph is a band.
TEST(SimSites, PathOverlapsStayWithinNeighbouringLegs) {
  const Site site = make_site("path", 1, 40);  // seven legs
  ASSERT_EQ(site.scan_poses.size(), 40u);
  const std::size_t middle = 20;
  int overlapping = 0;
  for (std::size_t j = 0; j < site.scan_poses.size(); ++j) {
    if (j == middle) continue;
    const double shared = overlap(site, middle, j);
    std::cout << "path overlap scan " << middle << "–" << j << ": " << shared << "\n";
    overlapping += shared > 0.05;
    if (j + 18 <= middle || j >= middle + 18) {
      EXPECT_LT(shared, 0.01) << "scan " << j;
    }
    if (j + 1 == middle || j == middle + 1) {
      EXPECT_GT(shared, 0.3) << "scan " << j;
    }
  }
  EXPECT_LE(overlapping, 16);
}

// Each scanner stands 1.5–1.8 m above the ground, nearly level, clear of
// walls, posts, trunks and cars (1.4 m around it up to 30° elevation), and
// not inside anything.
TEST_P(SimSitesEachSite, ScanPosesStandClearAboveTheGround) {
  const Site site = make_site(GetParam(), 11);
  ASSERT_EQ(site.scan_poses.size(), 4u);
  for (const Eigen::Isometry3d& pose : site.scan_poses) {
    const Vector3d centre = pose.translation();
    const auto ground = site.scene.intersect({centre, -Vector3d::UnitZ()}, 0.0, 10.0);
    ASSERT_TRUE(ground.has_value());
    EXPECT_EQ(site.scene.object(ground->object).kind, "ground");
    EXPECT_GE(ground->distance_m, 1.5);
    EXPECT_LE(ground->distance_m, 1.8);
    EXPECT_GT(pose.linear().col(2).z(), std::cos(2.9 * std::numbers::pi / 180.0));
    for (int el = -30; el <= 90; el += 15) {
      for (int az = 0; az < 360; az += 10) {
        const auto hit = site.scene.intersect({centre, direction(az, el)}, 0.0, 1.4);
        EXPECT_TRUE(!hit || (el > 30 && hit->distance_m > 0.3))
            << "obstacle at az " << az << " el " << el << ": "
            << site.scene.object(hit->object).name;
      }
    }
  }
}

TEST_P(SimSitesEachSite, LongerCampaignsExtendTheDefaultOne) {
  const Site four = make_site(GetParam(), 5, 4);
  const Site seven = make_site(GetParam(), 5, 7);
  EXPECT_EQ(make_site(GetParam(), 5, 1).scan_poses.size(), 1u);
  ASSERT_EQ(seven.scan_poses.size(), 7u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_TRUE(four.scan_poses[i].isApprox(seven.scan_poses[i]));
  for (std::size_t i = 0; i < 7; ++i) {
    for (std::size_t j = i + 1; j < 7; ++j) {
      EXPECT_GT((seven.scan_poses[i].translation() - seven.scan_poses[j].translation()).norm(),
                3.0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SimSites, SimSitesEachSite, ::testing::Values("campus", "street", "path"));

TEST(SimSites, CampusOverlapFallsToAboutAThird) {
  for (const std::uint64_t seed : {1u, 2u}) {
    const Site site = make_site("campus", seed);
    const auto overlaps =
        consecutive_overlaps(site, ("campus_seed" + std::to_string(seed)).c_str());
    ASSERT_EQ(overlaps.size(), 3u);
    EXPECT_GT(overlaps.front(), 0.6);
    EXPECT_GE(overlaps.back(), 0.2);
    EXPECT_LE(overlaps.back(), 0.5);
  }
}

TEST(SimSites, StreetOverlapFallsAlongTheStreet) {
  const Site site = make_site("street", 1);
  const auto overlaps = consecutive_overlaps(site, "street_seed1");
  ASSERT_EQ(overlaps.size(), 3u);
  EXPECT_GT(overlaps.front(), overlaps.back());
}

// A hit on `material` at texture coordinates (u, v).
Hit hit_at(MaterialId material, double u, double v) {
  Hit hit;
  hit.normal = Vector3d::UnitZ();
  hit.uv_m = Eigen::Vector2d(u, v);
  hit.object = 1;
  hit.material = material;
  return hit;
}

float luminance(const Eigen::Vector3f& rgb) {
  return 0.2126f * rgb.x() + 0.7152f * rgb.y() + 0.0722f * rgb.z();
}

TEST(SimTextures, EveryPatternStaysInTheUnitRange) {
  Scene scene;
  scene.add_image(make_sign_image("TEST", 2.0, 0.5, 50.0));
  std::vector<MaterialId> ids;
  for (int p = 0; p <= static_cast<int>(Pattern::kImage); ++p) {
    Material m{"m",  Eigen::Vector3f(0.9f, 0.6f, 0.3f),
               0.9f, static_cast<Pattern>(p),
               0.3f, p == static_cast<int>(Pattern::kImage) ? 0 : -1};
    ids.push_back(scene.add_material(m));
  }
  for (const MaterialId id : ids) {
    for (int i = 0; i < 2000; ++i) {
      const Hit hit = hit_at(id, -50.0 + 0.0513 * i, 3.0 - 0.0371 * i);
      const Eigen::Vector3f albedo = surface_albedo(scene, hit);
      const float reflectance = surface_reflectance(scene, hit);
      EXPECT_TRUE(albedo.minCoeff() >= 0.0f && albedo.maxCoeff() <= 1.0f) << "pattern " << id;
      EXPECT_TRUE(reflectance >= 0.0f && reflectance <= 1.0f) << "pattern " << id;
    }
  }
}

// Mortar joints (the bottom 1 cm of each 8 cm course) differ clearly from
// the bricks in colour and return less laser light.
TEST(SimTextures, BrickShowsMortarJoints) {
  Scene scene;
  const MaterialId brick = scene.add_material(
      {"brick", Eigen::Vector3f(0.36f, 0.12f, 0.07f), 0.45f, Pattern::kBrick, 0.24f, -1});
  double brick_sum = 0.0, mortar_sum = 0.0, brick_refl = 0.0, mortar_refl = 0.0;
  for (int i = 0; i < 100; ++i) {
    const Hit in_brick = hit_at(brick, 0.037 + 0.113 * i, 0.04 + 0.08 * (i % 7));
    const Hit in_joint = hit_at(brick, 0.037 + 0.113 * i, 0.004 + 0.08 * (i % 7));
    brick_sum += luminance(surface_albedo(scene, in_brick));
    mortar_sum += luminance(surface_albedo(scene, in_joint));
    brick_refl += surface_reflectance(scene, in_brick);
    mortar_refl += surface_reflectance(scene, in_joint);
  }
  EXPECT_GT(std::abs(mortar_sum - brick_sum) / brick_sum, 0.5);
  EXPECT_LT(mortar_refl, 0.8 * brick_refl);
}

// Averaged over a footprint much larger than a joint, joint and brick
// centres look alike: what a scanner's pixel records, with no moiré.
TEST(SimTextures, FootprintAveragingRemovesDetailFinerThanTheFootprint) {
  Scene scene;
  const MaterialId brick = scene.add_material(
      {"brick", Eigen::Vector3f(0.36f, 0.12f, 0.07f), 0.45f, Pattern::kBrick, 0.24f, -1});
  double sharp_contrast = 0.0, blurred_contrast = 0.0;
  for (int i = 0; i < 50; ++i) {
    const Hit in_brick = hit_at(brick, 0.037 + 0.113 * i, 0.04 + 0.08 * (i % 7));
    const Hit in_joint = hit_at(brick, 0.037 + 0.113 * i, 0.004 + 0.08 * (i % 7));
    sharp_contrast += std::abs(luminance(surface_albedo(scene, in_brick)) -
                               luminance(surface_albedo(scene, in_joint)));
    blurred_contrast += std::abs(luminance(surface_albedo(scene, in_brick, 0.2)) -
                                 luminance(surface_albedo(scene, in_joint, 0.2)));
  }
  EXPECT_LT(blurred_contrast, 0.3 * sharp_contrast);
}

TEST(SimTextures, GlassIsDarkAndVegetationBrightInTheInfrared) {
  Scene scene;
  const MaterialId glass = scene.add_material(
      {"g", Eigen::Vector3f(0.1f, 0.12f, 0.14f), 0.05f, Pattern::kGlass, 1.0f, -1});
  const MaterialId grass = scene.add_material(
      {"l", Eigen::Vector3f(0.1f, 0.24f, 0.05f), 0.55f, Pattern::kGrass, 1.5f, -1});
  EXPECT_LE(surface_reflectance(scene, hit_at(glass, 0.3, 0.2)), 0.07f);
  EXPECT_GE(surface_reflectance(scene, hit_at(grass, 0.3, 0.2)), 0.4f);
}

// Dark lettering on a light panel, row 0 at the top, sized from the metres.
TEST(SimTextures, SignImageHasDarkLettersOnALightPanel) {
  const TextureImage sign = make_sign_image("Northrop Hall", 5.0, 0.8, 200.0);
  ASSERT_EQ(sign.columns, 1000);
  ASSERT_EQ(sign.rows, 160);
  ASSERT_EQ(sign.rgb.size(), 160000u);
  int dark = 0, light = 0, dark_middle_rows = 0;
  for (int r = 0; r < sign.rows; ++r) {
    for (int c = 0; c < sign.columns; ++c) {
      const float l = luminance(sign.rgb[static_cast<std::size_t>(r * sign.columns + c)]);
      dark += l < 0.1f;
      light += l > 0.6f;
      dark_middle_rows += l < 0.1f && r > 50 && r < 110 && c > 100 && c < 900;
    }
  }
  const double n = sign.rows * sign.columns;
  EXPECT_GT(dark / n, 0.08);  // letters (and the border)
  EXPECT_LT(dark / n, 0.45);
  EXPECT_GT(light / n, 0.5);  // the panel
  EXPECT_GT(dark_middle_rows, 5000);
}

TEST(SimTextures, ImageOutsideItsExtentUsesTheMaterialColour) {
  Scene scene;
  const int image = scene.add_image(make_sign_image("A", 1.0, 0.5, 40.0));
  const MaterialId id = scene.add_material(
      {"sign", Eigen::Vector3f(0.2f, 0.4f, 0.6f), 0.5f, Pattern::kImage, 1.0f, image});
  EXPECT_TRUE(
      surface_albedo(scene, hit_at(id, 1.5, 0.2)).isApprox(Eigen::Vector3f(0.2f, 0.4f, 0.6f)));
  EXPECT_TRUE(
      surface_albedo(scene, hit_at(id, 0.5, -0.1)).isApprox(Eigen::Vector3f(0.2f, 0.4f, 0.6f)));
  EXPECT_GT(luminance(surface_albedo(scene, hit_at(id, 0.1, 0.25))), 0.5f);  // inside: light panel
}

// From 20 m in front of north hall's sign, a 0.1° raster sees both the dark
// letters and the light panel on the sign object.
TEST(SimTextures, CampusSignIsLegibleFromTwentyMetres) {
  const Site site = make_site("campus", 9);
  const Scene& scene = site.scene;
  ObjectId sign = 0;
  for (const ObjectInfo& o : scene.objects()) {
    if (o.name == "north_hall/sign") sign = o.id;
  }
  ASSERT_NE(sign, 0);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
  for (const Primitive& p : scene.primitives()) {
    if (p.object != sign) continue;
    const Quad& q = std::get<Quad>(p.shape);
    centre = q.origin + 0.5 * (q.edge_u + q.edge_v);
    normal = q.edge_u.cross(q.edge_v).normalized();
  }
  const Vector3d eye = centre + 20.0 * normal;
  int dark = 0, light = 0;
  for (int r = -15; r <= 15; ++r) {
    for (int c = -80; c <= 80; ++c) {
      const Eigen::AngleAxisd yaw(c * 0.1 * std::numbers::pi / 180.0, Vector3d::UnitZ());
      const Vector3d side = normal.cross(Vector3d::UnitZ()).normalized();
      const Eigen::AngleAxisd pitch(r * 0.1 * std::numbers::pi / 180.0, side);
      const auto hit = scene.intersect({eye, (yaw * pitch * -normal).normalized()}, 0.1, 40.0);
      if (!hit || hit->object != sign) continue;
      const float l = luminance(surface_albedo(scene, *hit));
      dark += l < 0.1f;
      light += l > 0.5f;
    }
  }
  EXPECT_GT(dark, 100);
  EXPECT_GT(light, 300);
}

}  // namespace
}  // namespace scanbench::acquisition::sim
