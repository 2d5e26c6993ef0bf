// Merging registered scans by sampling rate (seed 004 §4.3): of the points
// that sample the same surface from several scans, keep only those of the
// scan that sampled it most finely. Decided per point, never per tile.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "acquisition/range_noise.hpp"
#include "registration/prepared_scan.hpp"

namespace scanbench::registration {

struct MergeSettings {
  // One σ(range) model for every scan; none: each scan's own (its
  // geometry's range_noise, estimated from the scan).
  std::optional<acquisition::RangeNoise> noise;
  // Same surface: the ranges along the other scan's beam agree within
  // range_sigmas combined noise σ plus that beam's footprint (the beam
  // centre and the point may be half a pixel apart on a slanted surface)...
  double range_sigmas = 4.0;
  // ... and the normals agree within this angle [deg] (a thin wall seen
  // from both sides is two surfaces).
  double max_normal_angle_deg = 30.0;
  // Sampling rates within this relative difference count as equal; the scan
  // listed first then keeps its points. Keeps the decision consistent from
  // both sides where two scans sample a surface equally finely.
  double tie_tolerance = 0.05;
  // Skip the projection into a spherical scan whose samples at the point's
  // position are coarser than the point's own whatever it measured there (a
  // lower bound of their area, allowing for the range tolerance and the
  // footprint). The decisions are the same without it; only the time
  // differs (a third less on the campus).
  bool bound_coarser_scans = true;
  int threads = 0;  // 0 = all cores; results do not depend on it
};

struct MergeScanResult {
  // Per pixel, row-major: 1 = the point belongs to the merged model.
  std::vector<std::uint8_t> keep;
  std::size_t in_model = 0;  // valid points that are not mixed pixels
  std::size_t kept = 0;
  std::size_t redundant = 0;  // in the model, but another scan sampled the surface more finely
  // (point, other scan) tests that bound_coarser_scans decided without a projection
  std::size_t decided_by_bound = 0;
};

struct MergeResult {
  std::vector<MergeScanResult> scans;
  std::size_t points = 0;  // in-model points examined, all scans
  double seconds = 0.0;
};

// A scan as one side of a comparison: the prepared scan (a spherical
// grid's without its points will do: they are recomputed as prepare_scan
// computes them, from the ranges, so the scan takes half the memory; its
// valid, intensity, colour, confidence and flags are not read), its position in
// the scan list (ties go to the scan listed first), its pose, and
// max_footprint_per_m of it (0 when settings.bound_coarser_scans is off).
struct MergeOperand {
  const PreparedScan* scan = nullptr;
  int index = 0;
  Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();
  float footprint_per_m = 0.0f;
};

// The largest footprint per metre of range among the model points of
// `scan`: what the area bound of bound_coarser_scans needs of it.
float max_footprint_per_m(const PreparedScan& scan);

// The merge of one scan s, one other scan at a time, so that a campaign
// need not be in memory at once: start_merge keeps every in-model point of
// s, each merge_with drops the kept points that scan o samples more finely,
// finish_merge counts. Comparing s with every other scan in list order
// gives merge_by_sampling_rate's result for s, counts included (leaving
// out a scan leaves its tests out of decided_by_bound); a scan
// that cannot share a surface with s (disjoint bounds) may be left out.
MergeScanResult start_merge(const PreparedScan& scan);
void merge_with(MergeScanResult& out, const MergeOperand& s, const MergeOperand& o,
                const MergeSettings& settings);
void finish_merge(MergeScanResult& out, const PreparedScan& scan);

// Decides, for every in-model point of every scan, whether another scan
// observed the same surface (projection into its grid, range and normal
// agreement) with a smaller sample area (PreparedScan::sample_area_m2, the
// Jacobian determinant of the map between the two range images); the point
// is kept only when none did. `T_world_scan[i]` is scan i's pose (asserted:
// one per scan). Points without a normal are compared on range alone.
MergeResult merge_by_sampling_rate(std::span<const PreparedScan> scans,
                                   std::span<const Eigen::Isometry3d> T_world_scan,
                                   const MergeSettings& settings);

}  // namespace scanbench::registration
