// Fast Point Feature Histograms (Rusu, Blodow and Beetz, "Fast Point
// Feature Histograms (FPFH) for 3D Registration", ICRA 2009): a 33-bin
// description of the surface around each point of a cloud with normals,
// invariant to the pose, which coarse registration matches between scans.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

// Three histograms of 11 bins (the angles α, φ, θ of Rusu et al.), each
// normalised to sum to 100.
using Fpfh = std::array<float, 33>;

struct FpfhSettings {
  double radius_m = 1.5;  // support: the neighbours within this distance
  int threads = 0;        // 0 = all cores; the result does not depend on it
};

struct FpfhResult {
  std::vector<Fpfh> features;           // one per point of the cloud
  std::vector<std::uint8_t> described;  // 0: no neighbour within the radius, no feature
};

// The FPFH of every point of `cloud` (points in one frame [m], unit
// normals). A point without neighbours in the radius has described[i] = 0
// and an all-zero feature.
FpfhResult compute_fpfh(const SampleCloud& cloud, const FpfhSettings& settings);

}  // namespace scanbench::registration
