#include "segmentation/region_grow.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "segmentation/pixel_set.hpp"

namespace scanbench::segmentation {

namespace {

float squared(float v) {
  return v * v;
}

float cos_of_degrees(double degrees) {
  return static_cast<float>(std::cos(std::min(degrees, 180.0) * std::numbers::pi / 180.0));
}

// Whether q continues the surface of its neighbour p: each point lies
// within `footprints` of p's footprint (plus 4 σ of range noise) of the
// other's tangent plane (both ways: at a silhouette the tangent plane holds
// the line of sight, so the ground behind a post lies in the post's plane,
// but the post does not lie in the ground's); along the beam where neither
// has a normal.
struct Continuity {
  const SegmentationGrid& g;
  float footprints;

  bool operator()(std::size_t p, std::size_t q) const {
    const Eigen::Vector3f& xp = g.point[p];
    const Eigen::Vector3f& xq = g.point[q];
    const Eigen::Vector3f& np = g.normal[p];
    const Eigen::Vector3f& nq = g.normal[q];
    const float range = xp.norm();
    const float allowed = footprints * g.footprint_m[p] + 4.0f * g.range_noise.sigma(range);
    const Eigen::Vector3f step = xq - xp;
    if (np.squaredNorm() == 0.0f && nq.squaredNorm() == 0.0f) {
      return std::abs(xq.norm() - range) <= allowed;
    }
    return std::abs(np.dot(step)) <= allowed && std::abs(nq.dot(step)) <= allowed;
  }
};

// One policy per channel: accept(p, q) for a step from region pixel p to
// its neighbour q, add(q) once q joins.
struct RangePolicy {
  Continuity surface;
  bool accept(std::size_t p, std::size_t q) const { return surface(p, q); }
  void add(std::size_t) {}
};

struct ColorPolicy {
  const SegmentationGrid& g;
  float step2, mean2;  // squared ΔE bounds; mean2 < 0: no mean test
  std::array<double, 3> sum{};
  std::size_t count = 0;

  bool accept(std::size_t p, std::size_t q) const {
    const auto& a = g.lab[p];
    const auto& b = g.lab[q];
    if (squared(a[0] - b[0]) + squared(a[1] - b[1]) + squared(a[2] - b[2]) > step2) return false;
    if (mean2 < 0.0f) return true;
    const double inverse = 1.0 / static_cast<double>(count);
    float d2 = 0.0f;
    for (int k = 0; k < 3; ++k) d2 += squared(static_cast<float>(sum[k] * inverse) - b[k]);
    return d2 <= mean2;
  }
  void add(std::size_t q) {
    for (int k = 0; k < 3; ++k) sum[k] += g.lab[q][k];
    ++count;
  }
};

struct IntensityPolicy {
  const SegmentationGrid& g;
  float step, mean;  // mean < 0: no mean test
  double sum = 0.0;
  std::size_t count = 0;

  bool accept(std::size_t p, std::size_t q) const {
    const float v = g.intensity[q];
    if (!(std::abs(v - g.intensity[p]) <= step)) return false;
    return mean < 0.0f ||
           std::abs(static_cast<float>(sum / static_cast<double>(count)) - v) <= mean;
  }
  void add(std::size_t q) {
    sum += g.intensity[q];
    ++count;
  }
};

struct NormalPolicy {
  const SegmentationGrid& g;
  float cos_step, cos_mean;  // cos_mean < -1: no mean test
  float plane_footprints;    // 0: no pixels taken by the plane test
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_sum = Eigen::Vector3d::Zero();
  std::size_t count = 0;

  bool accept(std::size_t p, std::size_t q) const {
    const Eigen::Vector3f& n = g.normal[q];
    const Eigen::Vector3f mean = normal_sum.cast<float>().normalized();
    if (n.squaredNorm() > 0.0f && n.dot(g.normal[p]) >= cos_step &&
        (cos_mean < -1.0f || n.dot(mean) >= cos_mean)) {
      return true;
    }
    // A normal blurred by a crease or missing next to an edge: the point
    // itself still lies on the region's plane.
    if (plane_footprints <= 0.0f || normal_sum.squaredNorm() == 0.0) return false;
    const Eigen::Vector3f centroid = (point_sum / static_cast<double>(count)).cast<float>();
    const Eigen::Vector3f& x = g.point[q];
    // The footprint of p, already in the region: q's own is stretched where
    // q is seen at a grazing angle, as a perpendicular surface is.
    return std::abs(mean.dot(x - centroid)) <=
           plane_footprints * g.footprint_m[p] + 2.0f * g.range_noise.sigma(x.norm());
  }
  void add(std::size_t q) {
    // Blurred normals of pixels taken by the plane test stay out of the mean.
    const Eigen::Vector3d n = g.normal[q].cast<double>();
    if (count == 0 || n.dot(normal_sum.normalized()) >= cos_mean) normal_sum += n;
    point_sum += g.point[q].cast<double>();
    ++count;
  }
};

// Whether the seed carries the channel the region grows on: the scan has
// it, and the seed's own value is there (a normal, a finite intensity).
bool seed_has_channel(const SegmentationGrid& grid, Channel channel, std::size_t seed) {
  switch (channel) {
    case Channel::kRange:
      return true;
    case Channel::kColor:
      return !grid.lab.empty();
    case Channel::kIntensity:
      return !grid.intensity.empty() && std::isfinite(grid.intensity[seed]);
    case Channel::kNormal:
      return grid.normal[seed].squaredNorm() > 0.0f;
  }
  return false;
}

}  // namespace

GrowSettings default_grow_settings(Channel channel) {
  GrowSettings settings;
  settings.channel = channel;
  switch (channel) {
    case Channel::kRange:
      settings.tolerance = 1.0;
      break;
    case Channel::kColor:
      settings.tolerance = 4.0;
      settings.continuity_footprints = 0.0;
      break;
    case Channel::kIntensity:
      settings.tolerance = 0.04;
      settings.continuity_footprints = 0.0;
      break;
    case Channel::kNormal:
      settings.tolerance = 6.0;
      break;
  }
  return settings;
}

RegionGrower::RegionGrower(const SegmentationGrid& grid)
    : grid_(grid), stamp_(grid.shape.pixel_count(), 0) {}

void RegionGrower::start_call() {
  if (++generation_ == 0) {  // wrapped after 2^32 calls: forget every stamp once
    std::fill(stamp_.begin(), stamp_.end(), 0);
    generation_ = 1;
  }
  queue_.clear();
}

template <typename Policy>
void RegionGrower::spread(std::size_t seed, const GrowSettings& settings,
                          std::span<const std::uint8_t> open, Policy policy) {
  const GridShape& shape = grid_.shape;
  const Continuity continuity{grid_, static_cast<float>(settings.continuity_footprints)};
  // The range channel's own test is continuity, at its tolerance.
  const bool check_continuity =
      settings.channel != Channel::kRange && settings.continuity_footprints > 0.0;
  const auto enqueue = [&](std::size_t i) {
    visit(i);
    policy.add(i);
    queue_.push_back(static_cast<std::uint32_t>(i));
  };
  enqueue(seed);
  const auto columns = static_cast<std::uint32_t>(shape.columns);
  for (std::size_t head = 0; head < queue_.size(); ++head) {
    const std::uint32_t p = queue_[head];
    shape.for_each_neighbour(static_cast<int>(p / columns), static_cast<int>(p % columns),
                             [&](int r, int c) {
                               const std::size_t q = shape.index(r, c);
                               if (!open[q] || !grid_.usable[q] || stamp_[q] == generation_) return;
                               if (settings.max_pixels != 0 && queue_.size() >= settings.max_pixels)
                                 return;
                               if (check_continuity && !continuity(p, q)) return;
                               if (!policy.accept(p, q)) return;
                               enqueue(q);
                             });
  }
}

GrowResult RegionGrower::grow(std::size_t seed, const GrowSettings& settings,
                              std::span<const std::uint8_t> open) {
  assert(seed < grid_.shape.pixel_count() && "seed outside the grid");
  assert(open.size() == grid_.shape.pixel_count() && "open mask of another grid");
  GrowResult result;
  if (!open[seed] || !grid_.usable[seed]) return result;
  result.seed_open = true;
  start_call();
  const auto tolerance = static_cast<float>(settings.tolerance);
  const float mean = static_cast<float>(settings.mean_factor) * tolerance;
  const bool with_mean = settings.mean_factor > 0.0;
  if (!seed_has_channel(grid_, settings.channel, seed)) {
    result.seed_lacks_channel = true;
    queue_.push_back(static_cast<std::uint32_t>(seed));
  } else if (settings.channel == Channel::kRange) {
    spread(seed, settings, open, RangePolicy{Continuity{grid_, tolerance}});
  } else if (settings.channel == Channel::kColor) {
    spread(seed, settings, open,
           ColorPolicy{grid_, tolerance * tolerance, with_mean ? mean * mean : -1.0f});
  } else if (settings.channel == Channel::kIntensity) {
    const float spread_unit = grid_.intensity_spread;
    spread(seed, settings, open,
           IntensityPolicy{grid_, tolerance * spread_unit, with_mean ? mean * spread_unit : -1.0f});
  } else {
    spread(
        seed, settings, open,
        NormalPolicy{grid_, cos_of_degrees(settings.tolerance),
                     with_mean ? cos_of_degrees(settings.mean_factor * settings.tolerance) : -2.0f,
                     with_mean ? static_cast<float>(settings.plane_footprints) : 0.0f});
  }
  result.reached_limit = settings.max_pixels != 0 && queue_.size() >= settings.max_pixels;
  result.pixels.assign(queue_.begin(), queue_.end());
  sort_pixels(result.pixels);
  return result;
}

}  // namespace scanbench::segmentation
