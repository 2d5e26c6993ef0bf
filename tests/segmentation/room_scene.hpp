// A hand-built panorama with exact per-pixel truth for the segmentation
// tests: a scanner 1.5 m above the floor of a 10 m × 10 m room without a
// ceiling. The +x wall has a window set 0.3 m back into it (the reveals are
// the wall's) and a red poster flush with it; the −x wall lies across the
// panorama's seam. 0.5° steps, 720 × 180 pixels, elevations −60° … +30°.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::test {

enum RoomObject : std::uint8_t {
  kNothing = 0,
  kFloor = 1,
  kWallPlusX = 2,
  kWindow = 3,
  kWallMinusX = 4,
  kWallPlusY = 5,
  kWallMinusY = 6,
  kPoster = 7,
};

struct RoomScan {
  acquisition::Scan scan;
  acquisition::ScanGeometry geometry;
  std::vector<std::uint8_t> truth;  // RoomObject per pixel
};

namespace room_detail {

// An axis-aligned rectangle: coordinate `axis` equals `at`; the other two
// (in x, y, z order) lie within [lo, hi].
struct Rect {
  int axis;
  double at;
  Eigen::Vector2d lo, hi;
  RoomObject object;
};

inline std::vector<Rect> room_rects() {
  using V = Eigen::Vector2d;
  return {
      {2, -1.5, V(-5, -5), V(5, 5), kFloor},
      {0, 5.0, V(-5, -1.5), V(-1, 3), kWallPlusX},
      {0, 5.0, V(1, -1.5), V(5, 3), kWallPlusX},
      {0, 5.0, V(-1, -1.5), V(1, 0), kWallPlusX},
      {0, 5.0, V(-1, 1.5), V(1, 3), kWallPlusX},
      {1, -1.0, V(5, 0), V(5.3, 1.5), kWallPlusX},  // reveals: y = ±1, z = 0 and 1.5
      {1, 1.0, V(5, 0), V(5.3, 1.5), kWallPlusX},
      {2, 0.0, V(5, -1), V(5.3, 1), kWallPlusX},
      {2, 1.5, V(5, -1), V(5.3, 1), kWallPlusX},
      {0, 5.3, V(-1, 0), V(1, 1.5), kWindow},
      {0, -5.0, V(-5, -1.5), V(5, 3), kWallMinusX},
      {1, 5.0, V(-5, -1.5), V(5, 3), kWallPlusY},
      {1, -5.0, V(-5, -1.5), V(5, 3), kWallMinusY},
  };
}

// Nearest hit along unit direction d from the origin: range (∞ when none)
// and the object.
inline std::pair<double, RoomObject> cast(const Eigen::Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  RoomObject object = kNothing;
  for (const Rect& r : room_rects()) {
    if (std::abs(d[r.axis]) < 1e-12) continue;
    const double t = r.at / d[r.axis];
    if (t <= 0 || t >= best) continue;
    const Eigen::Vector3d p = t * d;
    const int u = r.axis == 0 ? 1 : 0, v = r.axis == 2 ? 1 : 2;
    if (p[u] < r.lo.x() || p[u] > r.hi.x() || p[v] < r.lo.y() || p[v] > r.hi.y()) continue;
    best = t;
    object = r.object;
    if (object == kWallPlusX && r.axis == 0 && p.y() > 2 && p.y() < 4 && p.z() > -0.5 &&
        p.z() < 0.5) {
      object = kPoster;
    }
  }
  return {best, object};
}

inline std::array<std::uint8_t, 3> colour_of(RoomObject object) {
  switch (object) {
    case kFloor:
      return {120, 120, 120};
    case kWindow:
      return {40, 60, 90};
    case kPoster:
      return {200, 30, 30};
    default:
      return {200, 200, 190};
  }
}

inline float intensity_of(RoomObject object) {
  switch (object) {
    case kFloor:
      return 0.4f;
    case kWindow:
      return 0.1f;
    case kPoster:
      return 0.9f;
    default:
      return 0.6f;
  }
}

}  // namespace room_detail

inline RoomScan make_room_scan() {
  constexpr int kRows = 180, kColumns = 720;
  constexpr double kStep = 0.5 * std::numbers::pi / 180.0;
  RoomScan room;
  acquisition::Scan& scan = room.scan;
  scan = acquisition::make_empty_scan(kRows, kColumns, true, true);
  // Column 0 looks at azimuth −180° + ½ step: the −x wall straddles the seam.
  scan.angles = acquisition::SphericalAngles{-std::numbers::pi + 0.5 * kStep, kStep,
                                             30.0 * std::numbers::pi / 180.0, -kStep};
  room.truth.assign(scan.pixel_count(), kNothing);
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kColumns; ++col) {
      const std::size_t i = scan.index(row, col);
      const auto [range, object] =
          room_detail::cast(acquisition::direction_precise(scan, row, col));
      if (object == kNothing) continue;
      scan.valid[i] = 1;
      scan.range_m[i] = static_cast<float>(range);
      const auto colour = room_detail::colour_of(object);
      for (int k = 0; k < 3; ++k) scan.rgb[3 * i + k] = colour[k];
      scan.intensity[i] = room_detail::intensity_of(object);
      room.truth[i] = object;
    }
  }
  acquisition::GeometrySettings settings;
  settings.threads = 1;
  room.geometry = acquisition::compute_geometry(scan, settings).geometry;
  return room;
}

// The room, built once per test executable.
inline const RoomScan& shared_room() {
  static const RoomScan room = make_room_scan();
  return room;
}

}  // namespace scanbench::test
