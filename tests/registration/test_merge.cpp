// Merging by sampling rate on hand-built scans of one wall with known
// sampling rates: the finer scan keeps the shared surface, ties go to the
// scan listed first, mixed pixels never make it into the model; and, on the
// simulated campus, the shortcut that skips coarser scans decides the same.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include "registration/merge.hpp"
#include "registration/prepared_scan.hpp"
#include "registration/simulated_campus.hpp"

namespace scanbench::registration {
namespace {

using scanbench::test::kDeg;
constexpr int kSize = 30;         // rows and columns
constexpr double kStepDeg = 1.0;  // pixel centres from −14.5° to +14.5°
constexpr double kHalfWindowDeg = 0.5 * kSize * kStepDeg;
constexpr double kWallX = 10.0;  // the wall: the world plane x = 10 m

// A scan, its geometry and its pose, built by hand: the scanner at
// T_world_scan looks around its own +x axis on a 30 × 30 grid of 1° and sees
// the wall x = kWallX. The geometry is exact: footprint range · step, the
// wall's normal towards the scanner, confidence 1, no flags.
struct HandScan {
  acquisition::Scan scan;
  acquisition::ScanGeometry geometry;
};

HandScan wall_scan(const Eigen::Isometry3d& T_world_scan) {
  HandScan out;
  acquisition::Scan& scan = out.scan;
  scan = acquisition::make_empty_scan(kSize, kSize, false, false);
  const double step = kStepDeg * kDeg;
  const double start = 0.5 * (kSize - 1) * step;
  scan.angles = acquisition::SphericalAngles{start, -step, start, -step};
  scan.T_world_scan = T_world_scan;
  const std::size_t n = scan.pixel_count();
  out.geometry.footprint_m.assign(n, 0.0f);
  out.geometry.normal.assign(n, Eigen::Vector3f::Zero());
  out.geometry.confidence.assign(n, 0.0f);
  out.geometry.flags.assign(n, 0);
  const Eigen::Vector3d origin = T_world_scan.translation();
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const Eigen::Vector3d d_world =
          T_world_scan.linear() * acquisition::direction_precise(scan, row, col);
      if (std::abs(d_world.x()) < 1e-9) continue;
      const double range = (kWallX - origin.x()) / d_world.x();
      if (range <= 0.0) continue;
      const std::size_t i = scan.index(row, col);
      scan.valid[i] = 1;
      scan.range_m[i] = static_cast<float>(range);
      const Eigen::Vector3d facing(d_world.x() > 0 ? -1.0 : 1.0, 0.0, 0.0);
      out.geometry.footprint_m[i] = static_cast<float>(range * step);
      out.geometry.normal[i] = (T_world_scan.linear().transpose() * facing).cast<float>();
      out.geometry.confidence[i] = 1.0f;
    }
  }
  return out;
}

Eigen::Isometry3d pose_at(double x, double heading_deg = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(heading_deg * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, 0.0, 0.0);
  return T;
}

// Prepares every hand scan (which must stay alive) and merges them at their poses.
MergeResult merge(const std::vector<HandScan>& hand, const MergeSettings& settings = {}) {
  std::vector<PreparedScan> prepared;
  std::vector<Eigen::Isometry3d> poses;
  for (const HandScan& h : hand) {
    prepared.push_back(prepare_scan(h.scan, h.geometry, 1));
    poses.push_back(h.scan.T_world_scan);
  }
  return merge_by_sampling_rate(prepared, poses, settings);
}

std::size_t count_valid(const HandScan& h) {
  return acquisition::count_valid(h.scan);
}

void expect_consistent_counts(const MergeScanResult& r, std::size_t in_model) {
  EXPECT_EQ(r.in_model, in_model);
  EXPECT_EQ(r.kept + r.redundant, r.in_model);
  std::size_t kept = 0;
  for (const std::uint8_t k : r.keep) kept += k;
  EXPECT_EQ(kept, r.kept);
}

// Where a point of the world falls in the view of `h`: well inside its
// window (> 0), well outside (< 0), or within 0.2° of the window's edge (0).
int inside_view(const HandScan& h, const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d p = h.scan.T_world_scan.inverse() * p_world;
  const double az = std::abs(std::atan2(p.y(), p.x())) / kDeg;
  const double el = std::abs(std::atan2(p.z(), std::hypot(p.x(), p.y()))) / kDeg;
  if (p.x() <= 0.0) return -1;
  if (az < kHalfWindowDeg - 0.2 && el < kHalfWindowDeg - 0.2) return 1;
  if (az > kHalfWindowDeg + 0.2 || el > kHalfWindowDeg + 0.2) return -1;
  return 0;
}

// Checks that `far`'s points are dropped exactly where `near` also sees the
// wall, and returns how many were clearly inside.
std::size_t expect_dropped_where_seen(const HandScan& far, const MergeScanResult& far_result,
                                      const HandScan& near, std::size_t& outside) {
  std::size_t inside = 0;
  outside = 0;
  for (int row = 0; row < far.scan.rows; ++row) {
    for (int col = 0; col < far.scan.columns; ++col) {
      const std::size_t i = far.scan.index(row, col);
      const int where = inside_view(near, acquisition::point_in_world(far.scan, row, col));
      if (where > 0) {
        EXPECT_EQ(far_result.keep[i], 0) << row << "," << col;
        ++inside;
      } else if (where < 0) {
        EXPECT_EQ(far_result.keep[i], 1) << row << "," << col;
        ++outside;
      }
    }
  }
  return inside;
}

TEST(MergeBySamplingRate, TheNearerScanKeepsTheSharedWall) {
  // Scanner 0 at 5 m from the wall, scanner 1 at 10 m, both facing it: the
  // near scan samples every shared spot about 3.5–4 times more finely (area
  // ∝ range² / cos incidence), and sees only the middle half of what the far
  // scan sees (±1.34 m of ±2.68 m at ±15°).
  const std::vector<HandScan> hand{wall_scan(pose_at(5.0)), wall_scan(pose_at(0.0))};
  ASSERT_EQ(count_valid(hand[0]), 900u);
  ASSERT_EQ(count_valid(hand[1]), 900u);
  const MergeResult result = merge(hand);
  ASSERT_EQ(result.scans.size(), 2u);
  EXPECT_EQ(result.points, 1800u);
  const MergeScanResult& near = result.scans[0];
  const MergeScanResult& far = result.scans[1];
  expect_consistent_counts(near, 900);
  expect_consistent_counts(far, 900);
  EXPECT_EQ(near.kept, 900u);
  EXPECT_EQ(near.redundant, 0u);
  std::size_t outside = 0;
  const std::size_t inside = expect_dropped_where_seen(hand[1], far, hand[0], outside);
  // The near window covers about the middle 15 × 15 pixels of the far one.
  EXPECT_GT(inside, 13u * 13u);
  EXPECT_GT(outside, 900u - 17u * 17u);
  EXPECT_GE(far.redundant, inside);
  EXPECT_LE(far.redundant, 900u - outside);
}

TEST(MergeBySamplingRate, TheListOrderDoesNotChangeWhoIsFiner) {
  const std::vector<HandScan> hand{wall_scan(pose_at(0.0)), wall_scan(pose_at(5.0))};
  const MergeResult result = merge(hand);
  ASSERT_EQ(result.scans.size(), 2u);
  EXPECT_EQ(result.scans[1].kept, 900u);  // the near scan, now second
  std::size_t outside = 0;
  const std::size_t inside = expect_dropped_where_seen(hand[0], result.scans[0], hand[1], outside);
  EXPECT_GT(inside, 13u * 13u);
  EXPECT_EQ(result.scans[0].redundant + result.scans[0].kept, 900u);
}

TEST(MergeBySamplingRate, EqualSamplingGoesToTheScanListedFirst) {
  // Two scanners at the same spot 5 m from the wall, the second turned 6.5°
  // to the left: where both see the wall they sample it equally finely.
  const std::vector<HandScan> hand{wall_scan(pose_at(5.0)), wall_scan(pose_at(5.0, 6.5))};
  for (const bool swapped : {false, true}) {
    SCOPED_TRACE(swapped ? "turned scan first" : "straight scan first");
    const std::vector<HandScan>& order =
        swapped ? std::vector<HandScan>{wall_scan(pose_at(5.0, 6.5)), wall_scan(pose_at(5.0))}
                : hand;
    const MergeResult result = merge(order);
    ASSERT_EQ(result.scans.size(), 2u);
    expect_consistent_counts(result.scans[0], 900);
    expect_consistent_counts(result.scans[1], 900);
    EXPECT_EQ(result.scans[0].kept, 900u);
    std::size_t outside = 0;
    const std::size_t inside =
        expect_dropped_where_seen(order[1], result.scans[1], order[0], outside);
    // 23 columns lie well inside the first scan's view, one on its edge, 6 outside.
    EXPECT_GE(inside, 22u * 29u);
    EXPECT_GE(outside, 6u * 30u);
  }
}

TEST(MergeBySamplingRate, AScanAloneKeepsEveryModelPoint) {
  std::vector<HandScan> hand{wall_scan(pose_at(5.0))};
  // A few pixels without a return and a few mixed pixels.
  for (std::size_t i = 0; i < 900; i += 37) hand[0].scan.valid[i] = 0;
  std::size_t mixed = 0;
  for (std::size_t i = 5; i < 900; i += 11) {
    if (!hand[0].scan.valid[i]) continue;
    hand[0].geometry.flags[i] |= acquisition::kFlagMixedPixel;
    ++mixed;
  }
  const std::size_t valid = count_valid(hand[0]);
  const MergeResult result = merge(hand);
  ASSERT_EQ(result.scans.size(), 1u);
  expect_consistent_counts(result.scans[0], valid - mixed);
  EXPECT_EQ(result.scans[0].kept, valid - mixed);
  EXPECT_EQ(result.scans[0].redundant, 0u);
  EXPECT_EQ(result.points, valid - mixed);
  for (std::size_t i = 0; i < 900; ++i) {
    const bool in_model = hand[0].scan.valid[i] && !hand[0].geometry.is_mixed(i);
    EXPECT_EQ(result.scans[0].keep[i], in_model ? 1 : 0) << i;
  }
}

TEST(MergeBySamplingRate, MixedPixelsAreNeverKept) {
  std::vector<HandScan> hand{wall_scan(pose_at(5.0)), wall_scan(pose_at(0.0))};
  std::size_t mixed[2] = {0, 0};
  for (std::size_t s = 0; s < 2; ++s) {
    for (std::size_t i = 3 + s; i < 900; i += 7) {
      hand[s].geometry.flags[i] |= acquisition::kFlagMixedPixel;
      ++mixed[s];
    }
  }
  const MergeResult result = merge(hand);
  ASSERT_EQ(result.scans.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    SCOPED_TRACE(s);
    expect_consistent_counts(result.scans[s], 900 - mixed[s]);
    for (std::size_t i = 0; i < 900; ++i) {
      if (hand[s].geometry.is_mixed(i)) {
        EXPECT_EQ(result.scans[s].keep[i], 0) << i;
      }
    }
  }
  EXPECT_EQ(result.points, 1800u - mixed[0] - mixed[1]);
  EXPECT_EQ(result.scans[0].kept, 900u - mixed[0]);  // the near scan loses no real point
  EXPECT_GT(result.scans[1].redundant, 13u * 13u - mixed[1]);
}

TEST(MergeBySamplingRate, TheTwoSidesOfAWallAreDifferentSurfaces) {
  // Scanner 1 looks at the same plane from behind (turned 180°): ranges agree
  // but the normals are opposite, so neither scan's points are redundant.
  const std::vector<HandScan> hand{wall_scan(pose_at(5.0)), wall_scan(pose_at(15.0, 180.0))};
  ASSERT_EQ(count_valid(hand[1]), 900u);
  const MergeResult result = merge(hand);
  EXPECT_EQ(result.scans[0].kept, 900u);
  EXPECT_EQ(result.scans[1].kept, 900u);
}

TEST(MergeBySamplingRate, AnotherSurfaceOnTheBeamIsNotTheSameSurface) {
  // The far scan's ranges lengthened by 1 m: it saw a surface about 1 m
  // behind the near scan's wall, with the same normal, so nothing is redundant.
  std::vector<HandScan> hand{wall_scan(pose_at(5.0)), wall_scan(pose_at(0.0))};
  for (float& range : hand[1].scan.range_m) range += 1.0f;
  const MergeResult result = merge(hand);
  EXPECT_EQ(result.scans[0].kept, 900u);
  EXPECT_EQ(result.scans[1].kept, 900u);
}

TEST(MergeBySamplingRate, EachScanIsJudgedWithinItsOwnNoise) {
  // The far scan reads 0.3 m long. With the default σ (5 mm), that is
  // another surface; from a sensor whose geometry estimated σ = 8 cm, it
  // is the same wall within 4 σ, and the near scan samples it more finely.
  std::vector<HandScan> hand{wall_scan(pose_at(5.0)), wall_scan(pose_at(0.0))};
  for (float& range : hand[1].scan.range_m) range += 0.3f;
  EXPECT_EQ(merge(hand).scans[1].kept, 900u);
  hand[1].geometry.range_noise = acquisition::RangeNoise{0.08, 0.0, 0.0};
  const MergeResult noisy = merge(hand);
  EXPECT_EQ(noisy.scans[0].kept, 900u);
  EXPECT_GT(noisy.scans[1].redundant, 13u * 13u);
  // One model for every scan, when the settings give it, overrides both.
  MergeSettings one_model;
  one_model.noise = acquisition::RangeNoise{};
  EXPECT_EQ(merge(hand, one_model).scans[1].kept, 900u);
}

TEST(MergeBySamplingRate, ResultsDoNotDependOnTheThreadCount) {
  const std::vector<HandScan> hand{wall_scan(pose_at(5.0)), wall_scan(pose_at(0.0)),
                                   wall_scan(pose_at(2.0, 10.0))};
  MergeSettings one_thread;
  one_thread.threads = 1;
  const MergeResult one = merge(hand, one_thread);
  const MergeResult all = merge(hand);
  ASSERT_EQ(one.scans.size(), 3u);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_EQ(one.scans[s].keep, all.scans[s].keep) << s;
    EXPECT_EQ(one.scans[s].kept, all.scans[s].kept) << s;
  }
}

std::vector<std::uint8_t> merged_keep(const std::vector<HandScan>& hand, std::size_t scan,
                                      bool bound) {
  MergeSettings settings;
  settings.bound_coarser_scans = bound;
  return merge(hand, settings).scans[scan].keep;
}

// The first scan's ranges read 2 cm short, within the range tolerance: its
// samples are smaller than the second scan's points, at their true distance
// from it, suggest. Its sample areas then lie within 5 % (a tie, which the
// first scan wins) of the second's, where a bound taken at the true distance
// would already call the first scan coarser.
TEST(MergeBySamplingRate, TheCoarserScanBoundAllowsForRangesReadShort) {
  std::vector<HandScan> hand{wall_scan(pose_at(8.0)), wall_scan(pose_at(8.063))};
  for (float& range : hand[0].scan.range_m) {
    if (range > 0.0f) range -= 0.02f;
  }
  const std::vector<std::uint8_t> with_bound = merged_keep(hand, 1, true);
  const std::vector<std::uint8_t> without_bound = merged_keep(hand, 1, false);
  EXPECT_EQ(with_bound, without_bound);
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < without_bound.size(); ++i) {
    dropped += hand[1].scan.valid[i] && without_bound[i] == 0;
  }
  EXPECT_GT(dropped, 0u);  // the ties exist
}

// The bound on the other scan's sample area only skips projections whose
// outcome it knows: the simulated campus gives the same keep masks with it.
TEST(MergeBySamplingRate, TheCoarserScanBoundChangesNoDecision) {
  const test::SimulatedCampus& site = test::campus(3);
  MergeSettings with_bound;
  MergeSettings without_bound;
  without_bound.bound_coarser_scans = false;
  const MergeResult fast = merge_by_sampling_rate(site.prepared, site.true_poses, with_bound);
  const MergeResult full = merge_by_sampling_rate(site.prepared, site.true_poses, without_bound);
  ASSERT_EQ(fast.scans.size(), 3u);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_EQ(fast.scans[s].keep, full.scans[s].keep) << s;
    EXPECT_GT(full.scans[s].redundant, 0u) << s;  // the scans do share surfaces
    EXPECT_GT(fast.scans[s].decided_by_bound, 0u) << s;
    EXPECT_EQ(full.scans[s].decided_by_bound, 0u) << s;
  }
}

}  // namespace
}  // namespace scanbench::registration
