// FPFH, after Rusu, Blodow and Beetz (ICRA 2009), section IV.
//
// For a point pair (p_s, n_s), (p_t, n_t), with d = p_t − p_s, the source
// is the one whose normal is nearer to the line between them (so the pair
// gives the same angles whichever point asks). In the Darboux frame
// u = n_s, v = u × d/|d|, w = u × v:
//   α = v · n_t,   φ = u · d/|d|,   θ = atan2(w · n_t, u · n_t)     (eq. 1)
// The Simplified PFH of a point bins these three angles over its
// neighbours in 11 bins each. Its FPFH adds its neighbours' SPFH weighted
// by the inverse of their distance ω_k (eq. 2):
//   FPFH(p) = SPFH(p) + 1/k Σ_k SPFH(p_k) / ω_k
// and each of the three histograms is rescaled to sum to 100, so that
// features of sparse and dense neighbourhoods compare. This is the paper's
// weighting; PCL's FPFH weights by 1/ω_k² and leaves SPFH(p) out.
#include "registration/fpfh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "core/parallel.hpp"
#include "registration/nearest_points.hpp"

namespace scanbench::registration {
namespace {

constexpr int kBins = 11;

struct PairAngles {
  float alpha = 0.0f;  // [-1, 1]
  float phi = 0.0f;    // [-1, 1]
  float theta = 0.0f;  // [-π, π]
};

// Equation 1; false for coincident points or a normal along their line.
bool pair_angles(const Eigen::Vector3f& p1, const Eigen::Vector3f& n1, const Eigen::Vector3f& p2,
                 const Eigen::Vector3f& n2, PairAngles& angles) {
  Eigen::Vector3f d = p2 - p1;
  const float length = d.norm();
  if (length <= 0.0f) return false;
  d /= length;
  Eigen::Vector3f u = n1, n_t = n2;
  float phi = u.dot(d);
  if (std::abs(n2.dot(d)) > std::abs(phi)) {  // p2's normal is nearer the line: p2 is the source
    u = n2;
    n_t = n1;
    d = -d;
    phi = u.dot(d);
  }
  Eigen::Vector3f v = u.cross(d);
  const float v_length = v.norm();
  if (v_length <= 1e-12f) return false;
  v /= v_length;
  const Eigen::Vector3f w = u.cross(v);
  angles = {v.dot(n_t), phi, std::atan2(w.dot(n_t), u.dot(n_t))};
  return true;
}

int bin_of(float value, float low, float high) {
  const int bin = static_cast<int>(std::floor(kBins * (value - low) / (high - low)));
  return std::clamp(bin, 0, kBins - 1);
}

// Each of the three 11-bin histograms scaled to sum to 100 (an empty one
// stays zero).
void normalise(Fpfh& histogram) {
  for (int part = 0; part < 3; ++part) {
    float sum = 0.0f;
    for (int b = 0; b < kBins; ++b) sum += histogram[part * kBins + b];
    if (sum <= 0.0f) continue;
    for (int b = 0; b < kBins; ++b) histogram[part * kBins + b] *= 100.0f / sum;
  }
}

// The SPFH of point i over its neighbours; false when no pair gave angles.
bool spfh(const SampleCloud& cloud, std::size_t i,
          const std::vector<std::pair<std::size_t, float>>& neighbours, Fpfh& histogram) {
  histogram.fill(0.0f);
  bool any = false;
  for (const auto& [j, squared] : neighbours) {
    PairAngles angles;
    if (j == i || !pair_angles(cloud.points[i], cloud.normals[i], cloud.points[j], cloud.normals[j],
                               angles)) {
      continue;
    }
    histogram[bin_of(angles.alpha, -1.0f, 1.0f)] += 1.0f;
    histogram[kBins + bin_of(angles.phi, -1.0f, 1.0f)] += 1.0f;
    histogram[2 * kBins +
              bin_of(angles.theta, -std::numbers::pi_v<float>, std::numbers::pi_v<float>)] += 1.0f;
    any = true;
  }
  normalise(histogram);
  return any;
}

}  // namespace

FpfhResult compute_fpfh(const SampleCloud& cloud, const FpfhSettings& settings) {
  const std::size_t n = cloud.size();
  const auto radius = static_cast<float>(settings.radius_m);
  const NearestRows<Eigen::Vector3f, 3> index(cloud.points);
  // Every point's neighbours, kept for the second pass: at a sample's
  // density (one point per voxel of a third of the radius) a few dozen.
  std::vector<std::vector<std::pair<std::size_t, float>>> neighbours(n);
  std::vector<Fpfh> simple(n);
  FpfhResult result;
  result.described.assign(n, 0);
  core::parallel_for_index(
      static_cast<int>(n), settings.threads,
      [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        index.within(cloud.points[i].data(), radius, neighbours[i]);
        // In index order, not the tree's: the sums below then do not
        // depend on how the tree split the points.
        std::sort(neighbours[i].begin(), neighbours[i].end());
        result.described[i] = spfh(cloud, i, neighbours[i], simple[i]) ? 1 : 0;
      },
      256);
  result.features.assign(n, Fpfh{});
  core::parallel_for_index(
      static_cast<int>(n), settings.threads,
      [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        if (!result.described[i]) return;
        Fpfh& feature = result.features[i];
        feature = simple[i];
        Fpfh others{};
        std::size_t count = 0;
        for (const auto& [j, squared] : neighbours[i]) {
          if (j == i || squared <= 0.0f) continue;
          const float weight = 1.0f / std::sqrt(squared);
          for (int b = 0; b < 3 * kBins; ++b) others[b] += weight * simple[j][b];
          ++count;
        }
        if (count > 0) {
          for (int b = 0; b < 3 * kBins; ++b) feature[b] += others[b] / static_cast<float>(count);
        }
        normalise(feature);
      },
      256);
  return result;
}

}  // namespace scanbench::registration
