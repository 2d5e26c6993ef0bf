// The scanner's range noise model, written once: the geometry stage's depth
// jump and mixed-pixel tests, the merge's same-surface test and the virtual
// scanner all use it.
#pragma once

namespace scanbench::acquisition {

// Standard deviation of a range reading, σ(range) = noise_m + noise_per_m ·
// range + noise_per_m2 · range² [m]. The constant and linear terms describe
// pulsed and phase-shift scanners; the quadratic one a triangulating sensor
// (structured light), whose depth error grows with the square of the range.
// The defaults are the RIEGL LMS-Z360's and our virtual scanner's.
struct RangeNoise {
  double noise_m = 0.005;
  double noise_per_m = 5e-5;  // [m per m of range]
  double noise_per_m2 = 0.0;  // [m per m² of range]

  double sigma(double range_m) const {
    return noise_m + (noise_per_m + noise_per_m2 * range_m) * range_m;
  }
  float sigma(float range_m) const {
    return static_cast<float>(noise_m) +
           (static_cast<float>(noise_per_m) + static_cast<float>(noise_per_m2) * range_m) * range_m;
  }
  bool operator==(const RangeNoise&) const = default;
};

}  // namespace scanbench::acquisition
