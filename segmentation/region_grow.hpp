// Seeded region growing on a scan's grid (seed 004 §4.1): from the pixel the
// user clicked, a region spreads to 8-neighbours that are open (inside the
// lasso, off the barriers, not yet assigned, in the model: constraints.hpp)
// and similar on the chosen channel:
//   range      continuity of the surface: the neighbour and the current
//              pixel each lie within tolerance footprints (plus 4 σ of range
//              noise) of the other's tangent plane (of those that have a
//              normal; along the beam when neither has one);
//   color      CIE L*a*b* ΔE to the neighbour ≤ tolerance, and to the
//              region's running mean ≤ mean_factor × tolerance;
//   intensity  difference to the neighbour ≤ tolerance × the scan's
//              intensity spread, and to the running mean ≤ mean_factor × that;
//   normal     angle to the neighbour's normal ≤ tolerance [deg], and to the
//              region's mean normal ≤ mean_factor × tolerance (so the gentle
//              turn of smoothed normals over a crease does not leak); or,
//              for the pixels next to a crease or edge whose fitted normal
//              is blurred or missing, a point within plane_footprints of the
//              plane through the region's centroid with its mean normal.
// The normal channel also stops at depth discontinuities (the range test
// with continuity_footprints), so a region never jumps from a façade to the
// pane behind it; colour and intensity ignore depth by default, so the
// foliage of a crown, many overlapping surfaces, is one region. Regions are
// breadth-first, so the running means and the result are deterministic.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "segmentation/segmentation_grid.hpp"

namespace scanbench::segmentation {

struct GrowSettings {
  Channel channel = Channel::kNormal;
  // The channel's step tolerance (units above); default_grow_settings gives
  // each channel's default.
  double tolerance = 6.0;
  // The bound on the distance to the running mean, in tolerances; 0 = no
  // mean test. Not used by the range channel.
  double mean_factor = 3.0;
  // The normal channel's plane test [footprints, plus 2 σ of range noise];
  // 0 = off. Only with the mean test: a curved region has no plane.
  double plane_footprints = 0.5;
  // The depth-discontinuity test [footprints, plus 4 σ of range noise] of
  // the colour, intensity and normal channels; 0 = off (the default of
  // colour and intensity). The range channel's test is its tolerance.
  double continuity_footprints = 1.0;
  // Stop once the region holds this many pixels; 0 = no limit.
  std::size_t max_pixels = 0;
};

// The defaults of `channel`: range 1 footprint; color ΔE 4 and intensity
// 0.04 spreads, both without the continuity test; normal 6°.
GrowSettings default_grow_settings(Channel channel);

struct GrowResult {
  std::vector<std::uint32_t> pixels;  // row-major indices, ascending; empty when the seed is closed
  bool seed_open = false;             // the seed was open: usable and not blocked
  // The region holds max_pixels pixels: it stopped there (and may or may
  // not have been complete).
  bool reached_limit = false;
  // The seed has no value on the channel (the scan has no colour or
  // intensity, or the seed's intensity is not finite, or the seed has no
  // normal): the region is the seed alone.
  bool seed_lacks_channel = false;
};

// Grows regions on one prepared grid. Keeps its work arrays between calls,
// so a click costs time in proportion to the region it grows and its
// boundary. One grower per thread.
class RegionGrower {
 public:
  // `grid` must outlive the grower. Allocates the work arrays (4 bytes per
  // pixel) once, here.
  explicit RegionGrower(const SegmentationGrid& grid);

  // Grows from pixel `seed` (row-major index, asserted inside the grid)
  // through pixels where open[i] != 0 (open has one byte per pixel,
  // asserted).
  GrowResult grow(std::size_t seed, const GrowSettings& settings,
                  std::span<const std::uint8_t> open);

 private:
  // Marks pixel i as seen in this call; false when it already was.
  bool visit(std::size_t i) {
    if (stamp_[i] == generation_) return false;
    stamp_[i] = generation_;
    return true;
  }
  void start_call();
  // The breadth-first spread from `seed` with the channel's Policy.
  template <typename Policy>
  void spread(std::size_t seed, const GrowSettings& settings, std::span<const std::uint8_t> open,
              Policy policy);

  const SegmentationGrid& grid_;
  std::vector<std::uint32_t> stamp_;  // generation_ where seen in the current call
  std::uint32_t generation_ = 0;
  std::vector<std::uint32_t> queue_;  // the region's pixels, breadth-first
};

}  // namespace scanbench::segmentation
