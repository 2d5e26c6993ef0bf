// FPFH features of two scans' samples, and their matching: each source
// feature with its nearest target features. The hypotheses drawn from the
// matches are coarse_hypotheses.hpp's.
#include "registration/feature_alignment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "core/parallel.hpp"
#include "core/timing.hpp"
#include "registration/nearest_points.hpp"

namespace scanbench::registration {

FeatureCloud::FeatureCloud(const SampleCloud& sample, const FeatureSettings& settings)
    : sample_(sample), fpfh_(compute_fpfh(sample, {settings.feature_radius_m, settings.threads})) {}

namespace {

// Every source sample with each of the `neighbours` target samples whose
// features are nearest to its own, in source order. Samples without a
// feature take no part.
std::vector<FeatureMatch> match_features(const FeatureCloud& source, const FeatureCloud& target,
                                         const FeatureSettings& settings) {
  std::vector<Fpfh> target_features;
  std::vector<std::size_t> target_sample;  // row of target_features → target sample
  for (std::size_t i = 0; i < target.size(); ++i) {
    if (!target.fpfh().described[i]) continue;
    target_features.push_back(target.fpfh().features[i]);
    target_sample.push_back(i);
  }
  if (target_features.empty()) return {};
  const NearestRows<Fpfh, 33> index(target_features);
  const auto k = static_cast<std::size_t>(std::max(1, settings.neighbours));
  // Unit normals' vertical components differ by at most 2: no filter.
  const double max_dz = settings.levelled ? settings.max_normal_z_difference : 2.0;
  const SampleCloud& s = source.sample();
  const SampleCloud& t = target.sample();
  // Slot i·k + j holds the source sample i's j-th match, when it has one.
  std::vector<std::optional<FeatureMatch>> slots(s.size() * k);
  core::parallel_for_index(
      static_cast<int>(s.size()), settings.threads,
      [&](int si) {
        const auto i = static_cast<std::size_t>(si);
        if (!source.fpfh().described[i]) return;
        std::vector<std::size_t> nearest;
        std::vector<float> distances;
        index.nearest(source.fpfh().features[i].data(), k, nearest, distances);
        for (std::size_t j = 0; j < nearest.size(); ++j) {
          const std::size_t ti = target_sample[nearest[j]];
          if (std::abs(s.normals[i].z() - t.normals[ti].z()) > max_dz) continue;
          slots[i * k + j] = FeatureMatch{s.points[i], s.normals[i], t.points[ti], t.normals[ti]};
        }
      },
      64);
  std::vector<FeatureMatch> matches;
  for (const std::optional<FeatureMatch>& slot : slots) {
    if (slot) matches.push_back(*slot);
  }
  return matches;
}

std::vector<PoseHypothesis> hypotheses_from(std::span<const FeatureMatch> matches,
                                            const FeatureSettings& settings) {
  if (settings.levelled) return levelled_hypotheses(matches, settings.hypotheses);
  return unlevelled_hypotheses(matches, settings.max_iterations, settings.similarity,
                               settings.hypotheses);
}

}  // namespace

FeatureAlignmentResult align_features(const FeatureCloud& source, const FeatureCloud& target,
                                      const FeatureSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  FeatureAlignmentResult result;
  if (source.size() < 3 || target.size() < 3) {
    result.failure = "too few points with normals for features";
  } else {
    const std::vector<FeatureMatch> matches = match_features(source, target, settings);
    result.matches = matches.size();
    for (PoseHypothesis& hypothesis : hypotheses_from(matches, settings)) {
      if (hypothesis.inliers >= settings.min_inliers) {
        result.hypotheses.push_back(std::move(hypothesis));
      }
    }
    if (result.hypotheses.empty()) {
      result.failure = "no pose agrees with " + std::to_string(settings.min_inliers) + " of the " +
                       std::to_string(matches.size()) + " feature matches";
    }
  }
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::registration
