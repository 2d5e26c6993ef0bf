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
#include "modeling/lod/memory_store.hpp"
#include "registration/simulated_campus.hpp"
#include "render/lod_renderer.hpp"
#include "render/pick.hpp"
#include "shared_device.hpp"
#include "support/test_support.hpp"

namespace scanbench::render {
namespace {

using registration::test::campus;

// Scan 0's in-model points in a store of round splats, origin at the
// scanner (positions kept to 0.1 mm), each point knowing its pixel; and the
// positions of those points, model frame, to aim at.
struct ScanStore {
  scanbench::test::ScratchDir dir;
  std::filesystem::path file;
  std::vector<Eigen::Vector3f> targets;
};

const ScanStore& scan_store() {
  static ScanStore s;  // its folder goes when the executable exits
  static const bool built = [] {
    const auto& site = campus(1);
    const registration::PreparedScan& prepared = site.prepared[0];
    const Eigen::Isometry3d& T = site.true_poses[0];
    std::vector<lod::PointToStore> points;
    for (std::size_t i = 0; i < prepared.in_model.size(); ++i) {
      if (!prepared.in_model[i]) continue;
      lod::PointToStore p;
      p.position = T * prepared.points[i].cast<double>();
      p.normal = T.linear().cast<float>() * site.geometry[0].normal[i];
      const float r = site.geometry[0].footprint_m[i];
      p.radii_m = Eigen::Vector2f(r, r);
      p.pixel = static_cast<std::uint32_t>(i);
      points.push_back(p);
      s.targets.push_back((p.position - T.translation()).cast<float>());
    }
    s.file = s.dir / "scan.sbproj.lod";
    lod::write_lod_store(s.file, T.translation(), {{0, 1, "scan", 0.0f, 1.0f, T}}, points);
    return true;
  }();
  static_cast<void>(built);
  return s;
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
  const ScanStore& store = scan_store();
  test::shared_device();
  LodRenderer renderer(store.file, {});
  RenderSettings settings;
  settings.splat_scale = 1.0f;
  const acquisition::RangeNoise noise;
  // Rays from 2 m above the scanner towards 300 random samples.
  std::mt19937 random(7);
  std::uniform_int_distribution<std::size_t> any(0, store.targets.size() - 1);
  const Eigen::Vector3f eye(0.0f, 0.0f, 2.0f);
  std::vector<double> point_sigmas, distance_sigmas;
  std::optional<Eigen::Vector3d> last_measured, last_true;
  double last_sigma = 0.0;
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3f target = store.targets[any(random)];
    const std::optional<LodPick> pick = renderer.pick(eye, (target - eye).normalized(), settings);
    if (!pick) continue;
    // Where the ray was aimed, or in front of it, and on the ray.
    const float aimed = (target - eye).norm();
    const float radius =
        std::max(lod::from_half(pick->point.radii[0]), lod::from_half(pick->point.radii[1]));
    EXPECT_LE(pick->distance_m, aimed + 4.0f * noise.sigma(aimed));
    EXPECT_LE((pick->position - eye - pick->distance_m * (target - eye).normalized()).norm(),
              radius + 1e-4f);
    const std::size_t pixel = pick->point.pixel;
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
