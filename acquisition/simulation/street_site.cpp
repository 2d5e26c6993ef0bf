// The "street" site: a 170 m street canyon lined on both sides by terraced
// shop houses of different widths and heights but one window spacing, so the
// façades repeat — hard for registration, which is the point. Trees, lamp
// posts and parked cars stand along the kerbs.
#include <algorithm>
#include <cstdio>
#include <numeric>
#include <string>

#include "acquisition/simulation/site_builder.hpp"

namespace scanbench::acquisition::sim::detail {
namespace {

using Eigen::Vector2d;

constexpr double kStreetEnd = 85.0;  // façades span x ∈ [−85, 85] [m]
constexpr double kSidewalk = 2.0;    // [m]
constexpr double kDepth = 12.0;      // building depth [m]

const char* const kShops[] = {
    "BAKERY",   "PHARMACY", "CAFE ROMA", "BOOKS",    "HARDWARE", "FLOWERS", "BARBER",   "DELI",
    "OPTICIAN", "SHOES",    "BANK",      "TAILOR",   "NEWS",     "GROCERY", "WINE BAR", "PIZZA",
    "TOYS",     "BIKES",    "TEA HOUSE", "JEWELLER", "LAUNDRY",  "BUTCHER", "GALLERY",  "POST"};

// In-place Fisher–Yates shuffle driven by our own generator (std::shuffle's
// draws are implementation-defined).
template <typename T>
void shuffle(std::vector<T>& items, Random& random) {
  for (int i = static_cast<int>(items.size()) - 1; i > 0; --i) {
    std::swap(items[static_cast<std::size_t>(i)],
              items[static_cast<std::size_t>(random.integer(0, i))]);
  }
}

// One row of terraced houses; side = +1 north of the street, −1 south.
void add_row(SiteBuilder& b, Random& random, double canyon_m, int side,
             std::vector<std::string>& shops) {
  const MaterialSet& m = b.materials();
  const MaterialId walls[] = {m.brick_red, m.brick_yellow, m.plaster_white, m.plaster_ochre,
                              m.stone};
  double x = -kStreetEnd;
  for (int index = 1; kStreetEnd - x >= 8.0; ++index) {
    double width = std::min(random.uniform(10.0, 18.0), kStreetEnd - x);
    if (kStreetEnd - x - width < 8.0) width = kStreetEnd - x;  // absorb a sliver at the end
    char name[32];
    std::snprintf(name, sizeof name, "%s_%02d", side > 0 ? "north" : "south", index);
    BuildingSpec spec =
        building_at(name, Vector2d(x + 0.5 * width, side * (0.5 * canyon_m + 0.5 * kDepth)),
                    Vector2d(width - 0.1, kDepth), 0.0, random.integer(2, 5));
    spec.ground_floor_height_m = 4.2;
    spec.floor_height_m = 3.2;
    spec.wall = walls[random.integer(0, 4)];
    spec.entrance_side = side > 0 ? 0 : 2;  // the side facing the street
    spec.windowed_sides = 1u << spec.entrance_side;
    spec.window_spacing_m = 2.6;
    spec.shop_front = true;
    spec.sign_text = shops.empty() ? "SHOP" : shops.back();
    if (!shops.empty()) shops.pop_back();
    b.add_building(spec);
    x += width;
  }
}

// Kerb slots every 6 m: a lamp post in every fourth, then five trees and
// four parked cars in slots drawn at random.
void add_kerb_items(SiteBuilder& b, Random& random, double canyon_m) {
  std::vector<Vector2d> free_slots;  // (x, side)
  int posts = 0;
  for (int i = 0; i < 28; ++i) {
    for (const int side : {1, -1}) {
      const double x = -81.0 + 6.0 * i;
      if ((i + (side > 0 ? 0 : 2)) % 4 == 0) {
        char name[32];
        std::snprintf(name, sizeof name, "lamp_post_%02d", ++posts);
        b.add_lamp_post(name, Vector2d(x, side * (0.5 * canyon_m - kSidewalk + 0.3)));
      } else {
        free_slots.emplace_back(x, side);
      }
    }
  }
  shuffle(free_slots, random);
  for (int i = 0; i < 5; ++i) {
    const Vector2d slot = free_slots[static_cast<std::size_t>(i)];
    // A braced list takes its draws in order; a Vector2d's y comes first
    // (random.hpp).
    const double trunk_radius = random.uniform(0.12, 0.22);
    const double crown_base = random.uniform(3.0, 3.6);
    const double crown_ry = random.uniform(1.6, 2.4);
    TreeSpec spec{trunk_radius, crown_base, Vector2d(random.uniform(1.2, 1.6), crown_ry),
                  random.integer(150, 300)};
    char name[32];
    std::snprintf(name, sizeof name, "tree_%02d", i + 1);
    b.add_tree(name, Vector2d(slot.x(), slot.y() * (0.5 * canyon_m - 1.2)), spec, random);
  }
  const MaterialId paints[] = {b.materials().paint_red, b.materials().paint_blue,
                               b.materials().paint_grey};
  for (int i = 0; i < 4; ++i) {
    const Vector2d slot = free_slots[static_cast<std::size_t>(5 + i)];
    b.add_car("car_0" + std::to_string(i + 1),
              Vector2d(slot.x(), slot.y() * (0.5 * canyon_m - kSidewalk - 1.0)),
              random.uniform(-0.03, 0.03), paints[i % 3]);
  }
}

}  // namespace

Site make_street(std::uint64_t seed, int scan_count) {
  Site site{"street", Scene{}, {}};
  Scene& scene = site.scene;
  const ObjectId root = scene.add_object("street", 0, "site");
  Random layout(hash_combine(seed, 0x737472656574ull));
  TerrainSettings terrain{0.01, 0.025, -0.2, 0.2, 0.12, 40.0};
  SiteBuilder builder(scene, random_terrain(layout, terrain), root);
  const double canyon = layout.uniform(11.0, 14.0);
  std::vector<std::string> shops(std::begin(kShops), std::end(kShops));
  shuffle(shops, layout);
  add_row(builder, layout, canyon, 1, shops);
  add_row(builder, layout, canyon, -1, shops);
  const MaterialSet m = builder.materials();
  builder.add_ground(
      GroundSpec{Eigen::AlignedBox2d(Vector2d(-100, -30), Vector2d(100, 30)), 1.25, 10.0},
      [&](const Vector2d& p) {
        const double across = std::abs(p.y());
        if (across < 0.5 * canyon - kSidewalk) return m.asphalt;
        return across < 0.5 * canyon + 1.0 ? m.paving : m.grass;
      });
  add_kerb_items(builder, layout, canyon);
  CampaignSettings campaign;
  campaign.loop = {{-60, 0.4}, {75, 0.4}, {75, -0.4}, {-75, -0.4}, {-75, 0.4}};
  campaign.gaps_m = {8.0, 20.0, 45.0};
  campaign.target_overlaps = {0.0, 0.0, 0.32};  // only the last gap is searched
  site.scan_poses = finish_site(builder, scene, campaign, seed, scan_count);
  return site;
}

}  // namespace scanbench::acquisition::sim::detail
