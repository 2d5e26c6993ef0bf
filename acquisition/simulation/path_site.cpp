// The "path" site: a street that grows with the campaign, for benches at
// scale. It runs east and north in turn, turning every 60 m, so it climbs a
// staircase across the terrain. Terraced houses line both sides and close
// the outer corner of every turn, so a station sees its own leg and a wedge
// of the next: the number of scans that overlap any one scan stays bounded
// however many stations the campaign has. Stations stand every 10 m along
// the centre line; both ends of the street are closed by a house.
//
// Each leg draws its houses, trees and cars from its own random stream, so a
// longer campaign extends a shorter one instead of reshuffling it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/simulation/site_builder.hpp"

namespace scanbench::acquisition::sim::detail {
namespace {

using Eigen::Vector2d;

constexpr double kLeg = 60.0;                   // centre line between turns [m]
constexpr double kHalfCanyon = 6.0;             // centre line to the façades [m]
constexpr double kDepth = 14.0;                 // house depth [m]
constexpr double kBack = kHalfCanyon + kDepth;  // centre line to the backs [m]
constexpr double kSidewalk = 2.0;               // [m]
constexpr double kFirstStation = 6.0;           // from the start of the centre line [m]
constexpr double kStationGap = 10.0;            // along the centre line [m]
constexpr double kRoomAfterLastStation = 20.0;  // jitter and spacing pushes [m]
constexpr int kMaxScans = 512;                  // keeps object ids within 16 bits

const char* const kTrades[] = {
    "ATELIER", "BAKERY", "BISTRO",  "BOOKS",  "BREWERY", "CAMERAS", "CHEESE", "CYCLES", "DENTIST",
    "FABRICS", "FRAMES", "GARAGE",  "HATS",   "KEYS",    "LAMPS",   "MARKET", "MUSIC",  "NOODLES",
    "PAINTS",  "PRINTS", "RECORDS", "SPICES", "STUDIO",  "TILES",   "WATCHES"};

// One straight stretch of the centre line, from `start` for kLeg metres,
// east on even legs and north on odd ones. "Left" is the side to the left
// of the direction of travel (north of an east leg, west of a north leg).
struct Leg {
  int index = 0;
  bool east = true;
  Vector2d start = Vector2d::Zero();
  Vector2d along = Vector2d::UnitX();
  Vector2d left = Vector2d::UnitY();
  double yaw_rad = 0.0;

  explicit Leg(int k)
      : index(k),
        east(k % 2 == 0),
        start(kLeg * ((k + 1) / 2), kLeg * (k / 2)),
        along(east ? Vector2d(1.0, 0.0) : Vector2d(0.0, 1.0)),
        left(east ? Vector2d(0.0, 1.0) : Vector2d(-1.0, 0.0)),
        yaw_rad(east ? 0.0 : 0.5 * std::numbers::pi) {}

  // World (x, y) at distance t along the leg and `across` to its left [m].
  Vector2d at(double t, double across) const { return start + t * along + across * left; }
  Vector2d end() const { return at(kLeg, 0.0); }
};

int leg_count(int scan_count) {
  const double length = kFirstStation + (scan_count - 1) * kStationGap + kRoomAfterLastStation;
  return std::max(1, static_cast<int>(std::ceil(length / kLeg)));
}

std::string leg_name(const Leg& leg, const char* part) {
  char name[48];
  std::snprintf(name, sizeof name, "leg%03d_%s", leg.index, part);
  return name;
}

// Extent of a row of houses along a leg, in metres from the leg's start.
// Every turn's corner blocks (inside and outside) belong to the east legs,
// so the rows of consecutive legs abut without overlapping; the first and
// the last leg run their rows on to the houses that close the street.
struct RowSpan {
  double from = 0.0;
  double to = 0.0;
};

RowSpan row_span(const Leg& leg, int side, bool first, bool last) {
  RowSpan span;
  if (leg.east) {
    span.from = side > 0 ? -kBack : kHalfCanyon;
    span.to = kLeg + (side > 0 ? -kHalfCanyon : kBack);
  } else {
    span.from = side > 0 ? kBack : -kHalfCanyon;
    span.to = kLeg + (side > 0 ? kHalfCanyon : -kBack);
  }
  if (first) span.from = -kBack;
  if (last) span.to = kLeg + kBack;
  return span;
}

BuildingSpec house(const Leg& leg, std::string name, double t_mid, double across, double length,
                   int street_side, Random& random) {
  BuildingSpec spec =
      building_at(std::move(name), leg.at(t_mid, across), Vector2d(length - 0.1, kDepth - 0.1),
                  leg.yaw_rad, random.integer(2, 5));
  spec.shop_front = random.uniform(0.0, 1.0) < 0.6;
  spec.ground_floor_height_m = spec.shop_front ? 4.2 : 3.4;
  spec.floor_height_m = random.uniform(2.9, 3.4);
  spec.entrance_side = street_side;
  spec.windowed_sides = 1u << street_side;
  spec.window_spacing_m = random.uniform(2.3, 3.4);
  char sign[32];
  const int number = random.integer(1, 99);  // drawn first (random.hpp)
  std::snprintf(sign, sizeof sign, "%s %d", kTrades[random.integer(0, 24)], number);
  spec.sign_text = sign;
  return spec;
}

// Terraced houses of different widths from span.from to span.to on one side
// (+1 left, −1 right), facing the street.
void add_row(SiteBuilder& b, const Leg& leg, int side, const RowSpan& span, Random& random) {
  const MaterialSet& m = b.materials();
  const MaterialId walls[] = {m.brick_red, m.brick_yellow, m.plaster_white, m.plaster_ochre,
                              m.stone};
  double t = span.from;
  for (int index = 1; span.to - t >= 6.0; ++index) {
    double width = std::min(random.uniform(8.0, 16.0), span.to - t);
    if (span.to - t - width < 6.0) width = span.to - t;  // absorb a sliver at the end
    char part[32];
    std::snprintf(part, sizeof part, "%s_%02d", side > 0 ? "left" : "right", index);
    BuildingSpec spec = house(leg, leg_name(leg, part), t + 0.5 * width,
                              side * (kHalfCanyon + 0.5 * kDepth), width, side > 0 ? 0 : 2, random);
    spec.wall = walls[random.integer(0, 4)];
    b.add_building(spec);
    t += width;
  }
}

// A house across the street at one end, facing along the leg.
void add_end_house(SiteBuilder& b, const Leg& leg, bool at_start, Random& random) {
  const double t_mid = at_start ? -0.5 * (kHalfCanyon + kBack) : kLeg + 0.5 * (kHalfCanyon + kBack);
  BuildingSpec spec =
      house(leg, at_start ? "start_house" : "end_house", t_mid, 0.0, kDepth, 0, random);
  spec.size = Vector2d(kDepth - 0.1, 2.0 * kHalfCanyon - 0.1);
  spec.entrance_side = at_start ? 1 : 3;  // facing +along or −along
  spec.windowed_sides = 1u << spec.entrance_side;
  spec.wall = b.materials().stone;
  b.add_building(spec);
}

// Kerb slots every 6 m clear of the crossings: lamp posts in every fourth,
// alternating sides, then a tree and two parked cars in slots drawn at random.
void add_kerb_items(SiteBuilder& b, const Leg& leg, Random& random) {
  std::vector<std::pair<double, int>> free_slots;  // (t, side)
  int posts = 0;
  for (int i = 0; 9.0 + 6.0 * i <= kLeg - 9.0; ++i) {
    for (const int side : {1, -1}) {
      const double t = 9.0 + 6.0 * i;
      if ((i + (side > 0 ? 0 : 2)) % 4 == 0) {
        char part[24];
        std::snprintf(part, sizeof part, "lamp_post_%d", ++posts);
        b.add_lamp_post(leg_name(leg, part), leg.at(t, side * (kHalfCanyon - kSidewalk + 0.3)));
      } else {
        free_slots.emplace_back(t, side);
      }
    }
  }
  const auto take_slot = [&] {
    const auto k =
        static_cast<std::size_t>(random.integer(0, static_cast<int>(free_slots.size()) - 1));
    const auto slot = free_slots[k];
    free_slots.erase(free_slots.begin() + static_cast<std::ptrdiff_t>(k));
    return slot;
  };
  const auto [tree_t, tree_side] = take_slot();
  // A braced list takes its draws in order; a Vector2d's y comes first
  // (random.hpp).
  const double trunk_radius = random.uniform(0.12, 0.22);
  const double crown_base = random.uniform(3.0, 3.6);
  const double crown_ry = random.uniform(1.6, 2.4);
  const TreeSpec tree{trunk_radius, crown_base, Vector2d(random.uniform(1.2, 1.6), crown_ry),
                      random.integer(150, 300)};
  b.add_tree(leg_name(leg, "tree"), leg.at(tree_t, tree_side * (kHalfCanyon - 1.2)), tree, random);
  const MaterialId paints[] = {b.materials().paint_red, b.materials().paint_blue,
                               b.materials().paint_grey};
  for (int i = 1; i <= 2; ++i) {
    const auto [t, side] = take_slot();
    const MaterialId paint = paints[random.integer(0, 2)];  // drawn first (random.hpp)
    b.add_car(leg_name(leg, i == 1 ? "car_1" : "car_2"),
              leg.at(t, side * (kHalfCanyon - kSidewalk - 1.0)),
              leg.yaw_rad + random.uniform(-0.03, 0.03), paint);
  }
}

// Distance from p to the centre line of legs k−1, k and k+1 [m].
double centre_line_distance(const Vector2d& p, int k, int legs) {
  double best = std::numeric_limits<double>::infinity();
  for (int j = std::max(0, k - 1); j <= std::min(legs - 1, k + 1); ++j) {
    const Leg leg(j);
    const double t = std::clamp((p - leg.start).dot(leg.along), 0.0, kLeg);
    best = std::min(best, (p - leg.at(t, 0.0)).norm());
  }
  return best;
}

// The ground of a leg in 10 m tiles: an east leg takes the corner squares
// at both of its ends, a north leg the stretch between them (and the end
// of the street when it is the last leg).
void add_leg_ground(SiteBuilder& b, const Leg& leg, int legs) {
  const bool last = leg.index == legs - 1;
  const double from = leg.east ? -kBack : kBack;
  const double to = leg.east || last ? kLeg + kBack : kLeg - kBack;
  const Vector2d a = leg.at(from, -kBack);
  const Vector2d c = leg.at(to, kBack);
  GroundSpec spec{Eigen::AlignedBox2d(a.cwiseMin(c), a.cwiseMax(c)), 1.25, 10.0,
                  leg_name(leg, "ground")};
  const MaterialSet m = b.materials();
  b.add_ground(spec, [&](const Vector2d& p) {
    const double across = centre_line_distance(p, leg.index, legs);
    if (across < kHalfCanyon - kSidewalk) return m.asphalt;
    return across < kHalfCanyon + 1.0 ? m.paving : m.grass;
  });
}

}  // namespace

int max_path_scans() {
  return kMaxScans;
}

Site make_path(std::uint64_t seed, int scan_count) {
  Site site{"path", Scene{}, {}};
  Scene& scene = site.scene;
  const ObjectId root = scene.add_object("path", 0, "site");
  Random layout(hash_combine(seed, 0x70617468ull));
  TerrainSettings terrain{0.004, 0.012, 0.0, 2.0 * std::numbers::pi, 0.12, 40.0};
  SiteBuilder builder(scene, random_terrain(layout, terrain), root);
  const int legs = leg_count(scan_count);
  CampaignSettings campaign;
  campaign.loop.push_back(Leg(0).at(kFirstStation, 0.0));
  for (int k = 0; k < legs; ++k) {
    const Leg leg(k);
    Random random(hash_combine(layout.next(), static_cast<std::uint64_t>(k)));
    // Kerb items first: they alone stand near the stations, and they come
    // out the same whether or not this leg is the last one.
    add_kerb_items(builder, leg, random);
    for (const int side : {1, -1}) {
      add_row(builder, leg, side, row_span(leg, side, k == 0, k == legs - 1), random);
    }
    if (k == 0) add_end_house(builder, leg, true, random);
    if (k == legs - 1) add_end_house(builder, leg, false, random);
    add_leg_ground(builder, leg, legs);
    campaign.loop.push_back(leg.end());
  }
  campaign.gaps_m = {kStationGap};
  site.scan_poses = finish_site(builder, scene, campaign, seed, scan_count);
  return site;
}

}  // namespace scanbench::acquisition::sim::detail
