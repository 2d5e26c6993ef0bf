// Three reduced-resolution scans of the simulated campus with their truth,
// geometry and prepared form: the shared input of the ICP and pipeline tests.
// Built once per test process (a few tenths of a second per scan).
#pragma once

#include <Eigen/Geometry>
#include <cassert>
#include <cstdint>
#include <numbers>
#include <utility>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/prepared_scan.hpp"
#include "support/test_support.hpp"

namespace scanbench::registration::test {

using scanbench::test::kDeg;

struct SimulatedCampus {
  static constexpr int kScans = 3;
  acquisition::sim::Site site = acquisition::sim::make_site("campus", 1, kScans);
  std::vector<Eigen::Isometry3d> true_poses = site.scan_poses;  // T_world_scan
  // The first scans of the campaign, as many as were asked for so far.
  std::vector<acquisition::Scan> scans;
  std::vector<acquisition::sim::ScanTruth> truth;
  std::vector<acquisition::ScanGeometry> geometry;
  std::vector<PreparedScan> prepared;

  SimulatedCampus() {
    // Reserved so that the PreparedScans' pointers stay valid as scans are added.
    scans.reserve(kScans);
    geometry.reserve(kScans);
  }

  // T_target_source of the truth: scan `source` in the frame of `target`.
  Eigen::Isometry3d true_relative(int target, int source) const {
    return true_poses[static_cast<std::size_t>(target)].inverse() *
           true_poses[static_cast<std::size_t>(source)];
  }
};

// The scanner at a quarter of the resolution in each direction (0.4° steps);
// sun shadows only colour the image, which registration does not read.
inline acquisition::sim::ScannerModel reduced_model() {
  acquisition::sim::ScannerModel model;
  model.columns = 900;
  model.rows = 225;
  model.shadows = false;
  return model;
}

// The campus with at least its first `count` scans (≤ kScans) simulated,
// their geometry computed and prepared. Scans are simulated once per test
// process, when first asked for.
inline const SimulatedCampus& campus(int count = SimulatedCampus::kScans) {
  namespace sim = acquisition::sim;
  static SimulatedCampus built;
  assert(count <= SimulatedCampus::kScans);
  while (static_cast<int>(built.scans.size()) < count) {
    const auto k = built.scans.size();
    const std::uint64_t seed = sim::hash_combine(1, static_cast<std::uint64_t>(k));
    sim::SimulatedScan simulated =
        sim::simulate_scan(built.site.scene, built.site.scan_poses[k], reduced_model(),
                           sim::random_lighting(seed), seed);
    built.geometry.push_back(acquisition::compute_geometry(simulated.scan).geometry);
    built.scans.push_back(std::move(simulated.scan));
    built.truth.push_back(std::move(simulated.truth));
    built.prepared.push_back(prepare_scan(built.scans.back(), built.geometry.back(), 0));
  }
  return built;
}

// Rotation [deg] and translation [m] between two poses.
struct PoseError {
  double rotation_deg = 0.0;
  double translation_m = 0.0;
};

inline PoseError pose_error(const Eigen::Isometry3d& truth, const Eigen::Isometry3d& estimate) {
  const auto [rotation, translation] = pose_change(truth, estimate);
  return {rotation / kDeg, translation};
}

}  // namespace scanbench::registration::test
