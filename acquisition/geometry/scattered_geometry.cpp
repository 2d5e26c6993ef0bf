#include "acquisition/geometry/scattered_geometry.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <nanoflann.hpp>

#include "core/parallel.hpp"
#include "core/timing.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::size_t kNear = 16;  // neighbours of the first fit (the point itself included)
constexpr std::size_t kWide = 64;  // of the second, where the first spans no plane
constexpr std::size_t kFootprintNeighbour = 4;
constexpr float kGapFactor = 3.0f;
constexpr float kFootprintFactor = 0.75f;
constexpr float kMinSpacingM = 1e-4f;  // 0.1 mm: points nearer are the same point
constexpr int kBlock = 4096;  // points per parallel task

// nanoflann's view of the points.
struct Cloud {
  const std::vector<Eigen::Vector3f>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return points[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using Tree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3>;

struct Fit {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  std::size_t used = 0;
  bool planar = false;
  double thickness = 0.0;  // the sum of squared distances to the plane [m²]
};

// The noise estimate (scattered_geometry.hpp): from fits of all kNear
// neighbours, ν = kNear − 3 degrees of freedom; the 30th percentile of
// √(χ²_ν / ν) for ν = 13 (simulated, 4·10⁵ draws) corrects the percentile.
constexpr double kNoisePercentile = 0.3;
constexpr double kChiPercentile = 0.874;
constexpr std::size_t kMinNoiseSamples = 100;
constexpr double kMinSigmaM = 1e-4;  // as the grid estimate's floor

// Plane through the found neighbours nearer than the gap limit.
Fit fit_plane(const std::vector<Eigen::Vector3f>& points, const std::uint32_t* found,
              const float* squared_distance, std::size_t count, float limit_squared) {
  Fit fit;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < count && squared_distance[k] <= limit_squared; ++k) {
    mean += points[found[k]].cast<double>();
    ++fit.used;
  }
  if (fit.used < 3) return fit;
  mean /= static_cast<double>(fit.used);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < fit.used; ++k) {
    const Eigen::Vector3d d = points[found[k]].cast<double>() - mean;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d lambda = solver.eigenvalues();  // ascending
  // A plane: the second spread well above the thickness, and the points
  // not on a line.
  fit.planar = lambda[1] > 4.0 * lambda[0] && lambda[1] > 1e-4 * lambda[2];
  fit.normal = solver.eigenvectors().col(0).cast<float>();
  fit.thickness = std::max(0.0, lambda[0]);
  return fit;
}

// σ of a cloud from its points' local σ (0: none), or `fallback` when
// fewer than kMinNoiseSamples have one.
NoiseEstimate estimate_cloud_noise(const Scan& scan, std::vector<float>& local_sigma,
                                   const RangeNoise& fallback) {
  NoiseEstimate out;
  out.noise = fallback;
  std::vector<float> ranges;
  std::size_t samples = 0;
  for (std::size_t i = 0; i < local_sigma.size(); ++i) {
    if (local_sigma[i] <= 0.0f) continue;
    local_sigma[samples++] = local_sigma[i];
    ranges.push_back(scan.range_m[i]);
  }
  if (samples < kMinNoiseSamples) return out;
  const auto at = [](std::vector<float>& values, std::size_t count, double share) {
    const auto k = static_cast<std::ptrdiff_t>(share * static_cast<double>(count - 1));
    std::nth_element(values.begin(), values.begin() + k,
                     values.begin() + static_cast<std::ptrdiff_t>(count));
    return static_cast<double>(values[static_cast<std::size_t>(k)]);
  };
  const double sigma =
      std::max(kMinSigmaM, at(local_sigma, samples, kNoisePercentile) / kChiPercentile);
  out.noise = RangeNoise{sigma, 0.0, 0.0};
  out.estimated = true;
  out.samples = samples;
  out.bands = {{at(ranges, samples, 0.5), sigma, samples}};
  return out;
}

}  // namespace

GeometryResult compute_scattered_geometry(const Scan& scan, const GeometrySettings& settings,
                                          const RecordedGeometry& recorded) {
  assert(scan.is_scattered() && "a scattered scan");
  assert((recorded.normal.empty() || recorded.normal.size() == scan.pixel_count()) &&
         (recorded.footprint_m.empty() || recorded.footprint_m.size() == scan.pixel_count()) &&
         "recorded geometry of one value per pixel");
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = count_valid(scan);  // the points fill pixels 0 … n − 1
  std::vector<Eigen::Vector3f> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    points[i] = scan.range_m[i] * std::get<PerPixelDirections>(scan.angles).directions[i];
  }
  GeometryResult result;
  ScanGeometry& g = result.geometry;
  const std::size_t pixels = scan.pixel_count();
  g.footprint_m.assign(pixels, 0.0f);
  g.normal.assign(pixels, Eigen::Vector3f::Zero());
  g.confidence.assign(pixels, 0.0f);
  g.flags.assign(pixels, 0);
  const Cloud cloud{points};
  const Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  const std::size_t near = std::min(kNear, n), wide = std::min(kWide, n);
  const int blocks = static_cast<int>((n + kBlock - 1) / kBlock);
  const auto for_each_point = [&](auto&& body) {
    core::parallel_for_index(blocks, settings.threads, [&](int block) {
      const std::size_t end = std::min(n, static_cast<std::size_t>(block + 1) * kBlock);
      for (std::size_t i = static_cast<std::size_t>(block) * kBlock; i < end; ++i) body(i);
    });
  };
  // Each point's sampling scale: the distance to its 4th nearest neighbour
  // apart from it (files repeat points: quantised coordinates, overlapping
  // tiles), at least the coordinates' resolution.
  std::vector<float> scale(n, 0.0f);
  for_each_point([&](std::size_t i) {
    std::array<std::uint32_t, kNear> found{};
    std::array<float, kNear> squared{};
    const std::size_t count = tree.knnSearch(points[i].data(), near, found.data(), squared.data());
    std::size_t apart = 0;
    float reach = 0.0f;
    for (std::size_t k = 0; k < count && apart < kFootprintNeighbour; ++k) {
      if (squared[k] <= kMinSpacingM * kMinSpacingM) continue;
      reach = squared[k];
      ++apart;
    }
    scale[i] = std::max(std::sqrt(reach), kMinSpacingM);
  });
  std::atomic<std::size_t> normals{0};
  // Each point's σ across its surface, from a plane through all its
  // kNear neighbours; 0 where there is none.
  std::vector<float> local_sigma(settings.estimate_range_noise ? n : 0, 0.0f);
  for_each_point([&](std::size_t i) {
    std::array<std::uint32_t, kWide> found{};
    std::array<float, kWide> squared{};
    const float* query = points[i].data();
    std::size_t count = tree.knnSearch(query, near, found.data(), squared.data());
    // A point much farther from its neighbours than they are from theirs
    // stands alone (an outlier, a stray return): no surface, and a
    // footprint at its neighbours' scale, not one that bridges the gap.
    std::array<float, kNear> around{};
    for (std::size_t k = 1; k < count; ++k) around[k - 1] = scale[found[k]];
    const auto middle = around.begin() + static_cast<std::ptrdiff_t>((count - 1) / 2);
    std::nth_element(around.begin(), middle,
                     around.begin() + static_cast<std::ptrdiff_t>(count - 1));
    const float local = count > 1 ? *middle : scale[i];
    const bool alone = scale[i] > kGapFactor * local;
    g.footprint_m[i] = kFootprintFactor * std::min(scale[i], kGapFactor * local);
    const float limit = kGapFactor * kGapFactor * scale[i] * scale[i];
    Fit fit = fit_plane(points, found.data(), squared.data(), count, limit);
    if (!local_sigma.empty() && fit.planar && fit.used == kNear && !alone) {
      local_sigma[i] = static_cast<float>(std::sqrt(fit.thickness / (kNear - 3)));
    }
    if (!fit.planar && wide > near) {
      // Wider: up to 3 × the 16th neighbour's distance, which reaches the
      // next line of a sampling denser along its lines than across them.
      const float wide_limit = std::max(limit, kGapFactor * kGapFactor * squared[count - 1]);
      count = tree.knnSearch(query, wide, found.data(), squared.data());
      fit = fit_plane(points, found.data(), squared.data(), count, wide_limit);
    }
    const Eigen::Vector3f towards_viewpoint = -points[i].normalized();
    if (alone || !fit.planar || fit.used < static_cast<std::size_t>(settings.min_neighbours) ||
        !fit.normal.allFinite() || !towards_viewpoint.allFinite()) {
      g.flags[i] |= kFlagNoNormal;
      return;
    }
    // The side: that of the normals the file recorded around the point,
    // where there are any (they face the scanner that saw the surface),
    // else the viewpoint's.
    Eigen::Vector3f side = towards_viewpoint;
    if (!recorded.normal.empty()) {
      Eigen::Vector3f around_sum = Eigen::Vector3f::Zero();
      for (std::size_t k = 0; k < count; ++k) around_sum += recorded.normal[found[k]];
      if (!around_sum.isZero()) side = around_sum;
    }
    if (fit.normal.dot(side) < 0.0f) fit.normal = -fit.normal;
    g.normal[i] = fit.normal;
    const float share = static_cast<float>(fit.used) / static_cast<float>(count);
    g.confidence[i] = std::max(1e-6f, share * std::abs(fit.normal.dot(towards_viewpoint)));
    ++normals;
  });
  std::atomic<std::size_t> kept{0};
  if (!recorded.empty()) {
    for_each_point([&](std::size_t i) {
      if (!recorded.footprint_m.empty() && recorded.footprint_m[i] > 0.0f)
        g.footprint_m[i] = recorded.footprint_m[i];
      if (recorded.normal.empty() || recorded.normal[i].isZero()) return;
      if (!g.has_normal(i)) ++normals;
      ++kept;
      g.normal[i] = recorded.normal[i];
      g.flags[i] = static_cast<std::uint8_t>(g.flags[i] & ~kFlagNoNormal);
      const float cosine = std::abs(g.normal[i].dot(points[i].normalized()));
      g.confidence[i] = std::max(1e-6f, std::isfinite(cosine) ? cosine : 0.0f);
    });
  }
  result.valid_points = n;
  result.normals = normals;
  result.recorded_normals = kept;
  result.noise = estimate_cloud_noise(scan, local_sigma, settings.range_noise);
  result.seconds = core::seconds_since(start);
  return result;
}

float scattered_sample_area_m2(float footprint_m) {
  const float step = footprint_m / kFootprintFactor;
  return step * step;
}

}  // namespace scanbench::acquisition
