// Picking on a simulated scan against the virtual scanner's truth. A pick
// is the first sample the ray meets, within its splat of the ray (never one
// behind the surface aimed at); being a measured sample, its coordinates
// are off the truth by the scanner's range noise (σ = 5 mm + 5·10⁻⁵ ·
// range), within 4 σ, and a distance between two picks by 4 times their
// combined σ at most.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "acquisition/range_noise.hpp"
#include "registration/simulated_campus.hpp"
#include "render/pick.hpp"

namespace scanbench::render {
namespace {

using registration::test::campus;

// Scan 0's in-model points as a render model of round splats, origin at
// the scanner. The model orders its points by tile, so each carries its
// pixel's index in `intensity` (exact: the reduced scan has 202 500 pixels,
// under 2^24).
RenderModel scan_model() {
  const auto& site = campus(1);
  const acquisition::Scan& scan = site.scans[0];
  const registration::PreparedScan& prepared = site.prepared[0];
  const Eigen::Isometry3d& T = site.true_poses[0];
  RenderPoints p;
  for (std::size_t i = 0; i < prepared.in_model.size(); ++i) {
    if (!prepared.in_model[i]) continue;
    p.position.push_back((T.linear() * prepared.points[i].cast<double>()).cast<float>());
    const Eigen::Vector3f n = site.geometry[0].normal[i];
    p.normal.push_back((T.linear().cast<float>() * n));
    const float r = site.geometry[0].footprint_m[i];
    p.radii_m.emplace_back(r, r);
    p.major_axis.push_back(Eigen::Vector3f::Zero());
    p.rgba.push_back({128, 128, 128, 255});
    p.intensity.push_back(static_cast<float>(i));
    p.node.push_back(0);
  }
  EXPECT_LT(scan.pixel_count(), std::size_t{1} << 24);
  return assemble_render_model(std::move(p), T.translation(), {}, {});
}

// The true position (model frame) of the sample `pixel`: on its beam, at the
// truth's noise-free range.
Eigen::Vector3d true_point(std::size_t pixel) {
  const auto& site = campus(1);
  const Eigen::Vector3d measured = site.prepared[0].points[pixel].cast<double>();
  const double scale = site.truth[0].range_m[pixel] / measured.norm();
  return site.true_poses[0].linear() * (measured * scale);
}

TEST(PickAccuracy, PickedPointsAndDistancesAreWithinTheScannersNoise) {
  const RenderModel model = scan_model();
  const acquisition::RangeNoise noise;
  // Rays from 2 m above the scanner towards 300 random samples.
  std::mt19937 random(7);
  std::uniform_int_distribution<std::size_t> any(0, model.points.size() - 1);
  const Eigen::Vector3f eye(0.0f, 0.0f, 2.0f);
  std::vector<double> point_sigmas, distance_sigmas;
  std::optional<Eigen::Vector3d> last_measured, last_true;
  double last_sigma = 0.0;
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3f target = model.points.position[any(random)];
    const std::optional<Pick> pick = pick_point(model, eye, (target - eye).normalized(), {}, 1.0f);
    if (!pick) continue;
    // Where the ray was aimed, or in front of it, and on the ray.
    const float aimed = (target - eye).norm();
    const float radius = model.points.radii_m[pick->point].maxCoeff();
    EXPECT_LE(pick->distance_m, aimed + 4.0f * noise.sigma(aimed));
    EXPECT_LE((pick->position - eye - pick->distance_m * (target - eye).normalized()).norm(),
              radius + 1e-4f);
    const auto pixel = static_cast<std::size_t>(model.points.intensity[pick->point]);
    if (campus(1).truth[0].mixed[pixel]) continue;  // a blend of two surfaces: no single truth
    const Eigen::Vector3d measured = pick->position.cast<double>();
    const Eigen::Vector3d truth = true_point(pixel);
    const double sigma = noise.sigma(truth.norm());
    point_sigmas.push_back((measured - truth).norm() / sigma);
    if (last_measured) {
      const double error =
          std::abs((measured - *last_measured).norm() - (truth - *last_true).norm());
      distance_sigmas.push_back(error / std::hypot(sigma, last_sigma));
    }
    last_measured = measured, last_true = truth, last_sigma = sigma;
  }
  ASSERT_GT(point_sigmas.size(), 250u);
  // Measured: every pick within 4 σ of the truth (the largest 3.2 σ), and
  // every distance within 4 σ of the two picks' combined noise.
  std::sort(point_sigmas.begin(), point_sigmas.end());
  std::sort(distance_sigmas.begin(), distance_sigmas.end());
  std::printf(
      "picks: %zu, worst %.2f σ, 99th percentile %.2f σ, median %.2f σ; distances: %zu, "
      "worst %.2f σ, median %.2f σ\n",
      point_sigmas.size(), point_sigmas.back(), point_sigmas[point_sigmas.size() * 99 / 100],
      point_sigmas[point_sigmas.size() / 2], distance_sigmas.size(), distance_sigmas.back(),
      distance_sigmas[distance_sigmas.size() / 2]);
  EXPECT_LT(point_sigmas.back(), 4.0) << "the worst pick";
  EXPECT_LT(distance_sigmas.back(), 4.0) << "the worst distance";
  EXPECT_LT(point_sigmas[point_sigmas.size() / 2], 1.0) << "the median pick";
}

}  // namespace
}  // namespace scanbench::render
