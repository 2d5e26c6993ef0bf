// The default scan campaign of a site: positions along a closed loop with
// growing spacing, so consecutive scans overlap a lot at first and little at
// the end, each with a random heading and small tilts like a tripod that was
// levelled by eye.
#include <cassert>
#include <cmath>
#include <numbers>

#include "acquisition/simulation/site_builder.hpp"

namespace scanbench::acquisition::sim::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Point at arc length s along the closed polyline (wrapping around), and the
// unit direction of travel there.
std::pair<Vector2d, Vector2d> along_loop(const std::vector<Vector2d>& loop, double s) {
  double total = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i)
    total += (loop[(i + 1) % loop.size()] - loop[i]).norm();
  s = std::fmod(s, total);
  for (std::size_t i = 0;; i = (i + 1) % loop.size()) {
    const Vector2d edge = loop[(i + 1) % loop.size()] - loop[i];
    if (s <= edge.norm()) return {loop[i] + edge.normalized() * s, edge.normalized()};
    s -= edge.norm();
  }
}

// The nominal position, or the nearest jittered one that keeps clear of
// every obstacle: jitter grows with each failed attempt.
Vector2d clear_position(const SiteBuilder& builder, const CampaignSettings& settings,
                        const Vector2d& nominal, const Vector2d& direction, Random& random) {
  const Vector2d side(-direction.y(), direction.x());
  for (int attempt = 0; attempt < 200; ++attempt) {
    const double spread = settings.jitter_m * (1.0 + attempt / 20.0);
    const double across = random.uniform(-0.5 * spread, 0.5 * spread);  // first (random.hpp)
    const Vector2d p = nominal + direction * random.uniform(-spread, spread) + side * across;
    if (builder.clearance(p) >= settings.min_clearance_m) return p;
  }
  assert(false && "no clear scan position near the campaign path");
  return nominal;
}

// Share of the hits seen from `from` that `to` sees from the front with a
// clear line of sight.
double seen_fraction(const Scene& scene, const Vector3d& from, const Vector3d& to) {
  constexpr double kRange = 100.0;
  constexpr double kStep = 2.0 * std::numbers::pi / 180.0;
  int hits = 0;
  int shared = 0;
  for (int el = -22; el < 23; ++el) {
    for (int az = 0; az < 180; ++az) {
      const Vector3d d(std::cos(el * kStep) * std::cos(az * kStep),
                       std::cos(el * kStep) * std::sin(az * kStep), std::sin(el * kStep));
      const auto hit = scene.intersect({from, d}, 0.1, kRange);
      if (!hit) continue;
      ++hits;
      const Vector3d to_other = to - (from + hit->distance_m * d);
      const double distance = to_other.norm();
      if (distance > kRange || hit->normal.dot(to_other) < 0.02 * distance) continue;
      shared += !scene.intersect({to, -to_other / distance}, 0.1, distance - 0.05);
    }
  }
  return hits == 0 ? 0.0 : static_cast<double>(shared) / hits;
}

Vector3d optical_centre(const SiteBuilder& builder, const Vector2d& xy, double height_m) {
  return {xy.x(), xy.y(), builder.ground_height(xy) + height_m};
}

bool too_close(const Vector2d& xy, const std::vector<Eigen::Isometry3d>& earlier) {
  constexpr double kMinSpacing = 5.0;  // [m]
  for (const Eigen::Isometry3d& pose : earlier) {
    if ((pose.translation().head<2>() - xy).norm() < kMinSpacing) return true;
  }
  return false;
}

// Arc length of the scan after the one at `previous`: the nominal gap, or,
// with a target overlap, the first candidate from 0.5 to 3 gaps (1 m steps)
// within 0.04 of it, else the closest. Each candidate has its own generator
// so the main one advances the same way whatever the search does.
Vector2d next_position(const SiteBuilder& builder, const Scene& scene, const CampaignSettings& c,
                       std::size_t gap, double& s, const std::vector<Eigen::Isometry3d>& earlier,
                       Random& random) {
  const double nominal = c.gaps_m[std::min(gap, c.gaps_m.size() - 1)];
  const std::uint64_t stream = random.next();
  const Vector3d previous = earlier.back().translation();
  if (gap >= c.target_overlaps.size() || c.target_overlaps[gap] <= 0.0) {
    s += nominal;
    for (int step = 0; step < 100 && too_close(along_loop(c.loop, s).first, earlier); ++step) {
      s += 2.0;  // a loop that passes an earlier scan again would repeat it
    }
    const auto [xy, direction] = along_loop(c.loop, s);
    Random local(stream);
    return clear_position(builder, c, xy, direction, local);
  }
  double best_error = 2.0;
  double best_s = s + nominal;
  Vector2d best_xy = Vector2d::Zero();
  const int candidates = static_cast<int>(2.5 * nominal) + 1;
  for (int k = 0; k < candidates && best_error > 0.04; ++k) {
    const double candidate = s + 0.5 * nominal + k;
    const auto [xy, direction] = along_loop(c.loop, candidate);
    Random local(hash_combine(stream, static_cast<std::uint64_t>(k)));
    const Vector2d clear = clear_position(builder, c, xy, direction, local);
    const double error =
        std::abs(estimate_overlap(scene, previous, optical_centre(builder, clear, 1.65)) -
                 c.target_overlaps[gap]);
    if (error < best_error) {
      best_error = error;
      best_s = candidate;
      best_xy = clear;
    }
  }
  s = best_s;
  return best_xy;
}

}  // namespace

double estimate_overlap(const Scene& scene, const Vector3d& a, const Vector3d& b) {
  return 0.5 * (seen_fraction(scene, a, b) + seen_fraction(scene, b, a));
}

std::vector<Eigen::Isometry3d> finish_site(const SiteBuilder& builder, Scene& scene,
                                           const CampaignSettings& settings, std::uint64_t seed,
                                           int count) {
  scene.build();
  Random scans(hash_combine(seed, 0x7363616e73ull));
  return plan_scan_poses(builder, scene, settings, count, scans);
}

std::vector<Eigen::Isometry3d> plan_scan_poses(const SiteBuilder& builder, const Scene& scene,
                                               const CampaignSettings& settings, int count,
                                               Random& random) {
  assert(count >= 1 && settings.loop.size() >= 2 && !settings.gaps_m.empty() &&
         "campaign needs scans, a loop and gaps");
  std::vector<Eigen::Isometry3d> poses;
  double s = 0.0;
  for (int i = 0; i < count; ++i) {
    Vector2d xy;
    if (i == 0) {
      const auto [start, direction] = along_loop(settings.loop, 0.0);
      xy = clear_position(builder, settings, start, direction, random);
    } else {
      xy = next_position(builder, scene, settings, static_cast<std::size_t>(i - 1), s, poses,
                         random);
    }
    const double height = random.uniform(1.52, 1.78);  // the mesh is within mm of the terrain
    const double yaw = random.uniform(0.0, 2.0 * std::numbers::pi);
    const double pitch = random.uniform(-settings.max_tilt_rad, settings.max_tilt_rad);
    const double roll = random.uniform(-settings.max_tilt_rad, settings.max_tilt_rad);
    Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();
    T_world_scan.translation() = optical_centre(builder, xy, height);
    T_world_scan.linear() =
        (Eigen::AngleAxisd(yaw, Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Vector3d::UnitX()))
            .toRotationMatrix();
    poses.push_back(T_world_scan);
  }
  return poses;
}

}  // namespace scanbench::acquisition::sim::detail
