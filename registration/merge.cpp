// Per-point redundancy test of seed 004 §4.3. For a point p of scan s and
// another scan o: project p into o's grid (projective association). When o
// saw a surface at that pixel at p's range (within the noise and o's
// footprint) with a normal that agrees, both scans sampled the same surface
// there. The surface area per sample, A = r² Ω / |cos θ| (range r, pixel solid
// angle Ω, incidence θ), is the inverse sampling rate; A_s / A_o is the
// Jacobian determinant of the warp from o's range image to s's. p is dropped
// when some o has A_o < A_s (o samples finer), with ties to the earlier scan.
#include "registration/merge.hpp"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <numbers>
#include <variant>

#include "core/parallel.hpp"
#include "core/timing.hpp"

namespace scanbench::registration {
namespace {

// Everything the test needs about the other scan o, in s's terms.
struct OtherScan {
  const PreparedScan* scan = nullptr;
  int index = 0;          // position in the scan list (tie-break)
  Eigen::Matrix3f R_o_s;  // rotation s → o
  Eigen::Vector3f t_o_s;  // translation s → o [m]
  // Spherical o: |Δazimuth · Δelevation| [sr] and |Δelevation| [rad]; 0 for
  // per-pixel grids.
  float step_solid_angle = 0.0f;
  float elevation_step = 0.0f;
  // 1 / (1 + F), F the largest footprint / range of o's model points.
  float inverse_footprint_growth = 1.0f;
};

// Covers the second-order terms the area bound below leaves out: the chords
// between neighbouring directions that give pixel solid angles are shorter
// than the arcs, and cos(el + Δ) ≥ cos el − |sin el| Δ holds only to first
// order (the rest is below cos el · Δ²/2).
constexpr float kBoundSlack = 0.99f;

struct Thresholds {
  float range_sigmas;
  float min_normal_cos;
  float tie_low;   // A_o < A_s · tie_low: o is finer (1 / tie_high: symmetric)
  float tie_high;  // A_o ≤ A_s · tie_high (and not finer): a tie
  std::optional<acquisition::RangeNoise> noise;  // MergeSettings::noise

  // σ of a range `scan` measured.
  float range_sigma(const PreparedScan& scan, float range) const {
    return range_noise_of(scan, noise).sigma(range);
  }
};

// True when spherical o samples the surface at point p (s's point, in o's
// frame at range r; sigma_p and sigma_s the range noise σ at r and at s's
// own range) more coarsely than s samples
// it (area_s), whatever o measured there: p then need not be projected.
// o's sample area is range_o² Ω / cos θ ≥ range_o² Ω (its value at normal
// incidence). The range test accepts only range_o ≥ r − tolerance −
// footprint_o, with tolerance ≤ range_sigmas (σ_p + σ_s) and footprint_o ≤
// F · range_o (F = max_footprint_per_m), so range_o ≥ r_lo = (r − range_sigmas
// (σ_p + σ_s)) / (1 + F). Ω = |Δaz Δel| cos(el') at the elevation el' of o's
// pixel row, within half a step of p's elevation el, and r² cos(el') ≥
// r² cos el − r² |sin el| δ = r (ρ − |z| δ) with δ a full step (ρ: horizontal
// distance; kBoundSlack covers the second-order rest).
bool coarser_by_bound(const Eigen::Vector3f& p, float r, float sigma_p, float sigma_s, float area_s,
                      const OtherScan& o, const Thresholds& t) {
  if (o.step_solid_angle <= 0.0f) return false;
  const float r_lo = (r - t.range_sigmas * (sigma_p + sigma_s)) * o.inverse_footprint_growth;
  if (r_lo <= 0.0f) return false;
  const float rho = std::sqrt(p.x() * p.x() + p.y() * p.y());
  const float min_area_o = kBoundSlack * (r_lo * r_lo / r) *
                           (rho - std::abs(p.z()) * o.elevation_step) * o.step_solid_angle;
  return min_area_o > area_s * t.tie_high;
}

// True when o sampled the surface of point i of s more finely (or equally
// finely and o comes first).
bool finer_elsewhere(const PreparedScan& s, int s_index, std::size_t i, const Eigen::Vector3f& p,
                     float range_p, float sigma_p, float sigma_s, const OtherScan& o,
                     const Thresholds& t) {
  // The grid's projection inlined: the merge runs it for every point and scan.
  const std::int64_t pixel = o.scan->grid ? o.scan->grid->pixel_of(p) : associate(*o.scan, p);
  if (pixel < 0) return false;
  const auto k = static_cast<std::size_t>(pixel);
  const float sigma = std::sqrt(sigma_p * sigma_p + sigma_s * sigma_s);
  const Eigen::Vector3f* normal = s.usable[i] ? &s.geometry->normal[i] : nullptr;
  if (!same_surface(*o.scan, k, range_p, sigma, normal, o.R_o_s, t.range_sigmas,
                    t.min_normal_cos)) {
    return false;
  }
  const float area_s = s.sample_area_m2[i];
  const float area_o = o.scan->sample_area_m2[k];
  if (area_o < area_s * t.tie_low) return true;
  return area_o <= area_s * t.tie_high && o.index < s_index;
}

// Decides row `row` of scan s against one other scan o, for the points no
// earlier comparison dropped; returns how many (point, o) tests the area
// bound decided. `directions` recomputes s's points where they were dropped
// (a spherical grid's; none where s has its points).
std::size_t merge_row(const PreparedScan& s, int s_index, const OtherScan& o, const Thresholds& t,
                      const acquisition::SphericalDirections* directions, int row,
                      MergeScanResult& out) {
  const int columns = s.scan->columns;
  std::size_t bounded = 0;
  for (int col = 0; col < columns; ++col) {
    const std::size_t i = s.scan->index(row, col);
    if (!out.keep[i]) continue;
    const float sigma_s = t.range_sigma(s, s.scan->range_m[i]);
    // As prepare_scan computes the point.
    const Eigen::Vector3f point_s =
        directions != nullptr ? s.scan->range_m[i] * (*directions)(row, col) : s.points[i];
    const Eigen::Vector3f p = o.R_o_s * point_s + o.t_o_s;
    const float range = p.norm();
    const float sigma_p = t.range_sigma(*o.scan, range);  // what o measures there
    if (coarser_by_bound(p, range, sigma_p, sigma_s, s.sample_area_m2[i], o, t)) {
      ++bounded;
    } else if (finer_elsewhere(s, s_index, i, p, range, sigma_p, sigma_s, o, t)) {
      out.keep[i] = 0;
    }
  }
  return bounded;
}

OtherScan other_scan(const MergeOperand& s, const MergeOperand& o, bool bound) {
  const Eigen::Isometry3d T_o_s = o.T_world_scan.inverse() * s.T_world_scan;
  OtherScan entry{o.scan, o.index, T_o_s.linear().cast<float>(), T_o_s.translation().cast<float>()};
  const auto* angles = std::get_if<acquisition::SphericalAngles>(&o.scan->scan->angles);
  if (angles != nullptr && bound) {
    entry.step_solid_angle =
        static_cast<float>(std::abs(angles->azimuth_step_rad * angles->elevation_step_rad));
    entry.elevation_step = static_cast<float>(std::abs(angles->elevation_step_rad));
    entry.inverse_footprint_growth = 1.0f / (1.0f + o.footprint_per_m);
  }
  return entry;
}

Thresholds thresholds_of(const MergeSettings& settings) {
  return {static_cast<float>(settings.range_sigmas),
          static_cast<float>(std::cos(settings.max_normal_angle_deg * std::numbers::pi / 180.0)),
          static_cast<float>(1.0 / (1.0 + settings.tie_tolerance)),
          static_cast<float>(1.0 + settings.tie_tolerance), settings.noise};
}

}  // namespace

float max_footprint_per_m(const PreparedScan& scan) {
  float largest = 0.0f;
  for (std::size_t k = 0; k < scan.in_model.size(); ++k) {
    if (scan.in_model[k]) {
      largest = std::max(largest, scan.geometry->footprint_m[k] / scan.scan->range_m[k]);
    }
  }
  return largest;
}

MergeScanResult start_merge(const PreparedScan& scan) {
  MergeScanResult out;
  out.keep = scan.in_model;
  return out;
}

void merge_with(MergeScanResult& out, const MergeOperand& s, const MergeOperand& o,
                const MergeSettings& settings) {
  assert(out.keep.size() == s.scan->in_model.size() && "start_merge(s) made `out`");
  const Thresholds thresholds = thresholds_of(settings);
  const OtherScan other = other_scan(s, o, settings.bound_coarser_scans);
  std::optional<acquisition::SphericalDirections> directions;
  if (s.scan->points.size() != s.scan->in_model.size()) {
    assert(s.scan->grid && "only a spherical grid's points may be dropped");
    directions.emplace(*s.scan->scan);
  }
  const acquisition::SphericalDirections* recompute = directions ? &*directions : nullptr;
  std::atomic<std::size_t> bounded{0};
  core::parallel_for_index(
      s.scan->scan->rows, settings.threads,
      [&](int row) {
        bounded += merge_row(*s.scan, s.index, other, thresholds, recompute, row, out);
      },
      4);
  out.decided_by_bound += bounded;
}

void finish_merge(MergeScanResult& out, const PreparedScan& scan) {
  out.in_model = 0;
  out.kept = 0;
  out.redundant = 0;
  for (std::size_t i = 0; i < out.keep.size(); ++i) {
    if (!scan.in_model[i]) continue;
    ++out.in_model;
    if (out.keep[i]) {
      ++out.kept;
    } else {
      ++out.redundant;
    }
  }
}

MergeResult merge_by_sampling_rate(std::span<const PreparedScan> scans,
                                   std::span<const Eigen::Isometry3d> T_world_scan,
                                   const MergeSettings& settings) {
  assert(scans.size() == T_world_scan.size() && "one pose per scan");
  const auto start = std::chrono::steady_clock::now();
  std::vector<MergeOperand> operands(scans.size());
  core::parallel_for_index(static_cast<int>(scans.size()), settings.threads, [&](int s) {
    const auto k = static_cast<std::size_t>(s);
    operands[k] = {&scans[k], s, T_world_scan[k],
                   settings.bound_coarser_scans ? max_footprint_per_m(scans[k]) : 0.0f};
  });
  MergeResult result;
  for (const MergeOperand& s : operands) {
    MergeScanResult out = start_merge(*s.scan);
    for (const MergeOperand& o : operands) {
      if (o.index != s.index) merge_with(out, s, o, settings);
    }
    finish_merge(out, *s.scan);
    result.points += out.in_model;
    result.scans.push_back(std::move(out));
  }
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::registration
