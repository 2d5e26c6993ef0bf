// The cameras the render benches look at the campus through (the same as
// scripts/views/campus_*.json, the demo's pictures), and which pixels of a
// truth picture a renderer can be held to.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "acquisition/camera_view.hpp"
#include "acquisition/simulation/truth_view.hpp"
#include "bench/simulated_site.hpp"

namespace scanbench::bench {

struct NamedView {
  const char* name;
  acquisition::CameraView camera;
};

// A camera at `position` looking at `target` [m, world].
acquisition::CameraView look(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                             double fov_deg, int width, int height);

// "closeup" (Keller Hall's west façade from 9 m), "street" (eye height
// across the quad) and "overview" (from 90 m up and away).
std::vector<NamedView> campus_views(int width, int height);

// 1 where the truth's surface was sampled by one of the scans (the first
// `scans` of them; none: all): the beam through it has an in-model return
// (not a mixed pixel) within two footprints (the geometry stage's,
// stretched by at most 4 at grazing incidence) and 2 cm of it.
std::vector<std::uint8_t> sampled_mask(const acquisition::sim::TruthImage& truth,
                                       const acquisition::CameraView& camera,
                                       const SimulatedSite& site,
                                       std::optional<std::size_t> scans = std::nullopt);

}  // namespace scanbench::bench
