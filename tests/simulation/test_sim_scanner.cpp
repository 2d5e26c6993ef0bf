// The virtual scanner's truth is right: measured against the scene itself.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "acquisition/formats/triplet_reader.hpp"
#include "acquisition/simulation/campaign.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/truth_view.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition::sim {
namespace {

using test::ScratchDir;

ScannerModel small_model() {
  ScannerModel model;
  model.columns = 720;
  model.rows = 180;
  return model;
}

// One small campus scan, shared by the tests of this file.
struct CampusScan {
  Site site = make_site("campus", 7, 2);
  SimulatedScan sim =
      simulate_scan(site.scene, site.scan_poses[0], small_model(), random_lighting(11), 11);
};

const CampusScan& campus() {
  static const CampusScan scan;
  return scan;
}

Eigen::Vector3d world_direction(const Scan& scan, int row, int col) {
  return scan.T_world_scan.linear() * direction_precise(scan, row, col);
}

TEST(SimScanner, MeasuredRangesLieOnTheTrueSurfaceWithinTheNoise) {
  const SimulatedScan& sim = campus().sim;
  const ScannerModel model = small_model();
  std::size_t checked = 0;
  for (std::size_t i = 0; i < sim.scan.pixel_count(); ++i) {
    if (!sim.scan.valid[i] || sim.truth.mixed[i]) continue;
    const double sigma = model.range_noise.sigma(sim.truth.range_m[i]);
    ASSERT_LT(std::abs(sim.scan.range_m[i] - sim.truth.range_m[i]), 6.0 * sigma) << i;
    ++checked;
  }
  EXPECT_GT(checked, sim.scan.pixel_count() / 3);
}

TEST(SimScanner, TruthIdsAndRangesMatchThePrimitivesOfThatObject) {
  const CampusScan& c = campus();
  const Scan& scan = c.sim.scan;
  int checked = 0;
  for (int row = 0; row < scan.rows; row += 7) {
    for (int col = 0; col < scan.columns; col += 13) {
      const std::size_t i = scan.index(row, col);
      const ObjectId id = c.sim.truth.object_id[i];
      if (id == 0) continue;
      // Brute force over the primitives of the truth object only, no BVH.
      const Ray ray{scan.T_world_scan.translation(), world_direction(scan, row, col)};
      double nearest = 1e30;
      for (const Primitive& p : c.site.scene.primitives()) {
        if (p.object != id) continue;
        if (const auto hit = intersect_shape(p.shape, ray, 0.0, 1e4))
          nearest = std::min(nearest, hit->distance_m);
      }
      ASSERT_NEAR(nearest, c.sim.truth.range_m[i], 1e-4) << "row " << row << " col " << col;
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
}

TEST(SimScanner, TruthNormalsAreUnitAndFaceTheScanner) {
  const SimulatedScan& sim = campus().sim;
  for (int row = 0; row < sim.scan.rows; ++row) {
    for (int col = 0; col < sim.scan.columns; ++col) {
      const std::size_t i = sim.scan.index(row, col);
      const Eigen::Vector3f n = sim.truth.normal_scan[i];
      if (sim.truth.object_id[i] == 0) {
        ASSERT_EQ(n, Eigen::Vector3f::Zero());
        continue;
      }
      ASSERT_NEAR(n.norm(), 1.0f, 1e-5f);
      ASSERT_LT(n.dot(direction(sim.scan, row, col)), 0.0f);
    }
  }
}

TEST(SimScanner, NoReturnWhereTheSkyIsAndAReturnWhereTheTruthHasAnObject) {
  const SimulatedScan& sim = campus().sim;
  for (std::size_t i = 0; i < sim.scan.pixel_count(); ++i) {
    ASSERT_EQ(sim.scan.valid[i] != 0, sim.truth.object_id[i] != 0) << i;
  }
  EXPECT_EQ(sim.scan.valid[0], 0);  // row 0 looks 50° up: sky
}

TEST(SimScanner, MixedPixelsFloatBetweenForegroundAndBackground) {
  const SimulatedScan& sim = campus().sim;
  std::size_t mixed = 0, floating = 0;
  for (std::size_t i = 0; i < sim.scan.pixel_count(); ++i) {
    if (!sim.truth.mixed[i]) continue;
    ++mixed;
    floating += std::abs(sim.scan.range_m[i] - sim.truth.range_m[i]) > 0.05f;
  }
  EXPECT_GT(mixed, 100u);
  EXPECT_LT(mixed, sim.scan.pixel_count() / 20);
  EXPECT_GT(floating, mixed / 2);  // most are visibly off the true surface
}

TEST(SimScanner, ResultDoesNotDependOnTheThreadCount) {
  const CampusScan& c = campus();
  SimulationSettings one_thread;
  one_thread.threads = 1;
  const SimulatedScan again = simulate_scan(c.site.scene, c.site.scan_poses[0], small_model(),
                                            random_lighting(11), 11, one_thread);
  EXPECT_EQ(again.scan.range_m, c.sim.scan.range_m);
  EXPECT_EQ(again.scan.rgb, c.sim.scan.rgb);
  EXPECT_EQ(again.scan.intensity, c.sim.scan.intensity);
  EXPECT_EQ(again.truth.mixed, c.sim.truth.mixed);
}

TEST(SimScanner, ScansOfTheSameWallDisagreeInColourButNotInGeometry) {
  const CampusScan& c = campus();
  const SimulatedScan relit =
      simulate_scan(c.site.scene, c.site.scan_poses[0], small_model(), random_lighting(99), 11);
  EXPECT_EQ(relit.truth.range_m, c.sim.truth.range_m);
  EXPECT_NE(relit.scan.rgb, c.sim.scan.rgb);
}

// The pinhole truth picture and a scan from the same place see the same
// objects in the same directions.
TEST(SimScanner, TruthViewAndScanAgreeOnObjectIds) {
  const CampusScan& c = campus();
  const Scan& scan = c.sim.scan;
  CameraView view;
  view.width = 160;
  view.height = 90;
  view.vertical_fov_deg = 40;
  view.T_world_camera.translation() = scan.T_world_scan.translation();
  // Look horizontally along the scan frame's x axis (camera z forward, y down).
  const Eigen::Vector3d forward = scan.T_world_scan.linear().col(0);
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  view.T_world_camera.linear() << right, Eigen::Vector3d(forward.cross(right)).normalized(),
      forward;
  const TruthImage image = render_truth_view(c.site.scene, view);
  const double focal = 0.5 * view.height / std::tan(0.5 * view.vertical_fov_deg * M_PI / 180.0);
  const auto& angles = std::get<SphericalAngles>(scan.angles);
  int compared = 0, agreed = 0;
  for (int v = 0; v < view.height; ++v) {
    for (int u = 0; u < view.width; ++u) {
      const Eigen::Vector3d d_world = view.T_world_camera.linear() *
                                      Eigen::Vector3d((u + 0.5 - 0.5 * view.width) / focal,
                                                      (v + 0.5 - 0.5 * view.height) / focal, 1.0);
      const Eigen::Vector3d d = scan.T_world_scan.linear().transpose() * d_world.normalized();
      const double az = std::atan2(d.y(), d.x()), el = std::asin(d.z());
      const int col =
          static_cast<int>(std::lround(std::remainder(az - angles.azimuth_start_rad, 2 * M_PI) /
                                           angles.azimuth_step_rad +
                                       scan.columns)) %
          scan.columns;
      const int row = static_cast<int>(
          std::lround((el - angles.elevation_start_rad) / angles.elevation_step_rad));
      if (row < 0 || row >= scan.rows) continue;
      ++compared;
      agreed += image.object_id[static_cast<std::size_t>(v) * view.width + u] ==
                c.sim.truth.object_id[scan.index(row, col)];
    }
  }
  EXPECT_GT(compared, view.width * view.height / 2);
  EXPECT_GT(agreed, 0.9 * compared);  // disagreement only along silhouettes
}

TEST(SimCampaign, SameSeedGivesByteIdenticalFiles) {
  ScratchDir a, b;
  CampaignSettings settings;
  core::Progress quiet;
  settings.scans = 2;
  settings.scanner.columns = 240;
  settings.scanner.rows = 60;
  settings.format = CampaignFormat::kBoth;
  settings.seed = 5;
  simulate_campaign(settings, a.path(), quiet);
  settings.simulation.threads = 1;
  simulate_campaign(settings, b.path(), quiet);
  int files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(a.path())) {
    if (!entry.is_regular_file()) continue;
    const auto relative = std::filesystem::relative(entry.path(), a.path());
    ASSERT_EQ(test::read_file_bytes(entry.path()), test::read_file_bytes(b.path() / relative))
        << relative;
    ++files;
  }
  EXPECT_EQ(files, 1 + 2 * (1 + 4 + 4));  // truth.json; per scan: ptx, triplet (4), truth (4)
}

TEST(SimCampaign, ADifferentSeedGivesADifferentCampaign) {
  ScratchDir a, b;
  CampaignSettings settings;
  core::Progress quiet;
  settings.scans = 1;
  settings.scanner.columns = 120;
  settings.scanner.rows = 30;
  simulate_campaign(settings, a.path(), quiet);
  settings.seed = 2;
  simulate_campaign(settings, b.path(), quiet);
  EXPECT_NE(test::read_file_bytes(a / "truth.json"), test::read_file_bytes(b / "truth.json"));
}

TEST(SimCampaign, TruthLoadsBackAndMatchesTheImportedScans) {
  ScratchDir dir;
  CampaignSettings settings;
  core::Progress quiet;
  settings.site = "street";
  settings.scans = 2;
  settings.scanner.columns = 360;
  settings.scanner.rows = 90;
  simulate_campaign(settings, dir.path(), quiet);
  const CampaignTruth truth = load_campaign_truth(dir / "truth.json");
  EXPECT_EQ(truth.site, "street");
  ASSERT_EQ(truth.scans.size(), 2u);
  EXPECT_FALSE(truth.objects.empty());
  for (const TruthScan& t : truth.scans) {
    ASSERT_EQ(t.scan_files.size(), 1u);
    const Scan scan = read_triplet(t.scan_files[0]);
    EXPECT_EQ(scan.T_world_scan.matrix(), t.T_world_scan.matrix());
    for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
      ASSERT_EQ(scan.valid[i] != 0, t.truth.object_id[i] != 0);
    }
  }
}

}  // namespace
}  // namespace scanbench::acquisition::sim
