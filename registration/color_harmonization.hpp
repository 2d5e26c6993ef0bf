// Colour harmonisation of registered scans (seed 004 §4.5): outdoor scans
// are taken over hours under other exposures and white balances, so one
// wall gets another colour in each scan. Corresponding points in the
// overlaps (the same surface sampled by two scans) give colour pairs; a
// robust least-squares problem (color_solver.hpp) solves for each scan's
// correction in linear RGB, where exposure and white balance act as
// per-channel gains:
//   gain-offset  rgb' = diag(g) · rgb + o   (6 parameters per scan)
//   matrix       rgb' = M · rgb + o         (12: also cross-talk between channels)
// In each group of scans linked by overlaps, the first scan (lowest index)
// is fixed (identity) and the others are brought to it. The residual and
// its loss are in color_costs.hpp.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <tuple>
#include <vector>

#include "acquisition/color_space.hpp"
#include "registration/prepared_scan.hpp"

namespace scanbench::registration {

enum class ColorModel { kGainOffset, kMatrix };
std::string_view color_model_name(ColorModel model);

struct ColorPairSettings {
  // Sample every stride-th pixel of every stride-th row of each scan,
  // from row and column `phase` (a phase other than the fit's samples
  // pixels the fit never saw: a held-out set).
  int stride = 2;
  int phase = 0;
  // Same surface: the point lies within this distance plus two footprints
  // of the other scan's point on its beam, and the normals (where both
  // have one) agree within max_normal_angle_deg.
  double max_distance_m = 0.02;
  double max_normal_angle_deg = 25.0;
  // Colours with a channel at or below `dark` or at or above `bright` (8-bit)
  // are left out: clipped or lost in noise, they follow no gain.
  int dark = 4;
  int bright = 250;
  // Only points whose colour differs from each of their 4 grid neighbours'
  // by at most this much (8-bit, any channel) in both scans: on texture,
  // shadow edges and object borders two scans' samples of "the same point"
  // see different colours through their different footprints, which no
  // correction should try to explain.
  int max_local_step = 8;
  // At most this many pairs per pair of scans, spread evenly over the
  // candidates (0: all).
  std::size_t max_pairs_per_overlap = 40000;
  // At most this many pairs of one scan with all the others (0: no bound),
  // split evenly among the scans it may overlap (link_pair_budget): six to
  // twelve parameters per scan need thousands of pairs, not hundreds of
  // thousands, and with the bound the solve grows with the number of scans,
  // not with the number of overlapping pairs. harmonize_project applies it;
  // find_color_pairs does not (it knows no overlap graph).
  std::size_t max_pairs_per_scan = 24000;
  int threads = 0;  // 0 = all cores; results do not depend on it
};

// The pairs to keep between two scans that may overlap `partners_a` and
// `partners_b` scans (each counting the other): the least of
// max_pairs_per_overlap and max_pairs_per_scan shared among the partners
// of the busier scan, at least 1; 0 (all) when neither bounds it.
std::size_t link_pair_budget(const ColorPairSettings& settings, std::size_t partners_a,
                             std::size_t partners_b);

// One corresponding point: its colour in two scans, linear RGB.
struct ColorPair {
  std::uint32_t scan_a = 0;
  std::uint32_t scan_b = 0;
  std::int64_t pixel_a = 0;  // row-major, in scan a
  std::int64_t pixel_b = 0;
  Eigen::Vector3f rgb_a = Eigen::Vector3f::Zero();
  Eigen::Vector3f rgb_b = Eigen::Vector3f::Zero();
};

// What of a scan the pair search takes as a pair's first scan: the pixels
// its sampling (stride, phase) takes that are in the model, of a usable
// colour and locally uniform, in row order, each with its point and normal
// in the scan frame and its linear colour. A few percent of the scan's
// bytes: a stage keeps these of the scans still to be paired, not the
// scans. Empty for a scan without colour.
struct ColorSamples {
  std::vector<std::int64_t> pixels;      // row-major
  std::vector<Eigen::Vector3f> points;   // scan frame [m]
  std::vector<Eigen::Vector3f> normals;  // scan frame, unit; zero where the pixel has none
  std::vector<Eigen::Vector3f> rgb;      // linear
  std::size_t size() const { return pixels.size(); }
  // Its arrays, for core::SpillShelf.
  auto vectors() { return std::tie(pixels, points, normals, rgb); }
  auto vectors() const { return std::tie(pixels, points, normals, rgb); }
};

// The samples of `scan` (prepared with its geometry) under `settings`
// (stride, phase, dark, bright, max_local_step, threads).
ColorSamples color_samples(const PreparedScan& scan, const ColorPairSettings& settings);

// The pairs of scans a and b (at positions ia < ib of the scan list, at
// poses T_world_a and T_world_b): a's samples, taken by color_samples under
// the same `settings`, projected into b's grid and tested there, thinned
// evenly to max_pairs_per_overlap, in a's row order. None when a has no
// samples or b no colour.
std::vector<ColorPair> color_pairs_between(const ColorSamples& a, const PreparedScan& b,
                                           std::uint32_t ia, std::uint32_t ib,
                                           const Eigen::Isometry3d& T_world_a,
                                           const Eigen::Isometry3d& T_world_b,
                                           const ColorPairSettings& settings);

// Pairs of every two scans, scan a < scan b, found by projecting a's
// sampled points into b's grid (registration/prepared_scan.hpp's
// association). Deterministic for any thread count. Scans without colour
// take part in none.
std::vector<ColorPair> find_color_pairs(std::span<const PreparedScan> scans,
                                        std::span<const Eigen::Isometry3d> T_world_scan,
                                        const ColorPairSettings& settings);

struct HarmonizeSettings {
  ColorModel model = ColorModel::kGainOffset;
  // Cauchy loss scale on the residual (color_costs.hpp), a difference of
  // soft logarithms: a relative colour difference (0.05: about 5 %).
  double loss_scale = 0.05;
  // Weight of each scan's pull towards the identity, × √(its pairs): a
  // gentle tie for scans the pairs constrain poorly.
  double prior_weight = 0.002;
  // Bounds: gains within [1 / max_gain_ratio, max_gain_ratio] (exposure 2
  // stops either way), cross-talk of the matrix model within
  // ±max_cross_talk, offsets within ±max_offset (linear RGB: flare and
  // black level are small).
  double max_gain_ratio = 4.0;
  double max_cross_talk = 0.1;
  double max_offset = 0.005;
  int max_iterations = 100;
  int threads = 0;
};

struct HarmonizeResult {
  // One per scan: the identity for each group's fixed scan and for scans in
  // no pair.
  std::vector<acquisition::ColorCorrection> corrections;
  // Per scan, the index of the fixed scan of its group of scans linked by
  // pairs (itself for that scan); -1 for a scan in no pair.
  std::vector<std::int32_t> reference;
  std::size_t pairs = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  bool converged = false;
};

// Solves the corrections of `scan_count` scans from `pairs`: Levenberg–
// Marquardt on the costs of color_costs.hpp under a Cauchy loss, within the
// settings' bounds (color_solver.hpp). `iterations` counts the steps tried.
HarmonizeResult harmonize_colors(std::span<const ColorPair> pairs, std::size_t scan_count,
                                 const HarmonizeSettings& settings);

}  // namespace scanbench::registration
