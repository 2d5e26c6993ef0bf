// A site's campaign scanned in memory, with its truth and per-point geometry:
// the common input of the registration and merge benches.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::bench {

struct SimulatedSite {
  std::string name;
  std::vector<acquisition::Scan> scans;  // at their true poses
  std::vector<acquisition::sim::ScanTruth> truth;
  std::vector<acquisition::ScanGeometry> geometry;
  std::vector<Eigen::Isometry3d> true_poses;
  std::vector<acquisition::sim::ObjectInfo> objects;  // the truth's hierarchy; id k at k − 1
};

// How the scans' colours are lit.
enum class SiteLighting {
  kPerScan,    // each scan its own sun, exposure and white balance (a real campaign)
  kReference,  // every scan under reference_lighting(), as the truth pictures are
  // The reference sun for every scan, each with its own exposure and white
  // balance: colours differ between scans by per-channel gains only.
  kExposureOnly,
};

// The seed of the site every bench simulates (its layout, trees, textures).
inline constexpr std::uint64_t kSiteSeed = 1;

// The simulation seed of scan k (0-based): simulating it again with another
// lighting gives the same geometry and noise, other colours.
std::uint64_t scan_seed(int k);

// The lighting of scan k (0-based) of a site simulated with `lighting`.
acquisition::sim::ScanLighting scan_lighting(SiteLighting lighting, int k);

// Scans the first `scan_count` positions of site `name` (seed 1) with `model`,
// then computes every scan's geometry with the default settings.
SimulatedSite simulate_site(const std::string& name, const acquisition::sim::ScannerModel& model,
                            int scan_count, SiteLighting lighting = SiteLighting::kPerScan);

// The campaign stored in a new project `file` at its true poses, with its
// geometry and the keep masks of a merge at those poses: the model
// `scanbench render` and `scanbench lod` read.
// `scans`: only the first so many (none: all).
void store_site_project(const SimulatedSite& site, const std::filesystem::path& file,
                        std::optional<std::size_t> scans = std::nullopt);

// Scan k of `site` added to `project` (holding scans 0…k − 1 of it, as
// store_site_project stored them) as a campaign grows: imported with its
// geometry in one command, then the first k + 1 scans merged again in
// another (their keep masks).
void add_site_scan(const SimulatedSite& site, std::size_t k, store::Project& project);

}  // namespace scanbench::bench
