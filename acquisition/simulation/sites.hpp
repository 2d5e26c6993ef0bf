// Procedural outdoor sites with a default scan campaign. Deterministic for a
// seed: the same (name, seed, scan_count) always builds the same scene.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/simulation/scene.hpp"

namespace scanbench::acquisition::sim {

struct Site {
  std::string name;
  Scene scene;  // built (ready for intersect)
  // T_world_scan of each scan position: the scanner's optical centre about
  // 1.5–1.8 m above the ground, a random heading and small random tilts
  // (up to ~2°), z of the scan frame near world up.
  std::vector<Eigen::Isometry3d> scan_poses;
};

// "campus", "street" and "path". The campus and the street are fixed sites
// whose campaigns close a loop; the path is a street that grows with its
// campaign (a new 60 m leg every six stations), so that each scan overlaps a
// bounded number of others however long the campaign: the site for benches
// at scale.
std::vector<std::string> site_names();

// The most scans a campaign on the named site can have.
int max_scan_count(std::string_view name);

// Builds the named site. Asserts `name` is one of site_names() and
// 1 ≤ scan_count ≤ max_scan_count(name). On the campus and the street,
// consecutive scan positions overlap a lot at first and less later, down to
// about 30 % for the last pair of a 4-scan campaign; on the path they stand
// 10 m apart along the street.
Site make_site(std::string_view name, std::uint64_t seed, int scan_count = 4);

}  // namespace scanbench::acquisition::sim
