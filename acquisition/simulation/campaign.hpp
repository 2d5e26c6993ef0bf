// A simulated scan campaign on disk: the scans in the formats the importers
// read, and beside them the exact truth (truth.json plus per-pixel images).
//
// Layout of an output folder DIR:
//   DIR/<site>_scan_<k>.ptx                  when the format includes ptx
//   DIR/<site>_scan_<k>.json (+ _range.tiff, _intensity.png, _color.png)
//                                            when it includes triplet
//   DIR/truth/<site>_scan_<k>_object_id.png  16-bit object id, 0 = no return
//   DIR/truth/<site>_scan_<k>_normal.tiff    float × 3, unit normal in the scan frame
//   DIR/truth/<site>_scan_<k>_range.tiff     float, noise-free range [m], 0 = no return
//   DIR/truth/<site>_scan_<k>_mixed.png      8-bit, 255 = mixed pixel
//   DIR/truth.json                           poses, file names, hierarchy, settings
// (k is 1-based, two digits.) The format of truth.json is in docs/simulation.md.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "core/progress.hpp"

namespace scanbench::acquisition::sim {

enum class CampaignFormat { kPtx, kTriplet, kBoth };

struct CampaignSettings {
  std::string site = "campus";
  std::uint64_t seed = 1;
  int scans = 4;
  ScannerModel scanner;
  CampaignFormat format = CampaignFormat::kTriplet;
  SimulationSettings simulation;
  // Pose error written into the scan files of every scan but the first, as
  // an uncalibrated instrument set-up would give (truth.json keeps the true
  // poses): up to this rotation [deg] and translation [m], seeded. 0 = exact.
  double pose_error_deg = 0.0;
  double pose_error_m = 0.0;
  // Every scan under one sun (one_sun_lighting: the scans' colours differ
  // by their exposure and white balance only) instead of each its own
  // (random_lighting).
  bool one_sun = false;
};

struct CampaignResult {
  std::vector<std::filesystem::path> scan_files;  // what `scanbench import` takes
  std::filesystem::path truth_json;
  double simulate_seconds = 0.0;  // ray casting only, all scans
  double total_seconds = 0.0;
};

// Builds the site, simulates every scan of its campaign and writes the layout
// above into `out_dir` (created when missing; existing files of the same
// names are replaced), reporting one unit of `progress` per scan written.
// Throws std::runtime_error naming the file when writing fails,
// core::Cancelled when cancelled between scans (the scans written so far
// stay). Asserts settings.site is a known site and scans ≥ 1.
CampaignResult simulate_campaign(const CampaignSettings& settings,
                                 const std::filesystem::path& out_dir, core::Progress& progress);

// One scan's truth as loaded back from a campaign folder.
struct TruthScan {
  std::string name;
  Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();
  ScanTruth truth;
  std::vector<std::filesystem::path> scan_files;  // ptx and/or triplet sidecar
};

struct CampaignTruth {
  std::string site;
  std::uint64_t seed = 0;
  int rows = 0;
  int columns = 0;
  std::vector<TruthScan> scans;
  std::vector<ObjectInfo> objects;
};

// Reads truth.json and the truth images it names. Throws InputError naming
// the file and the problem on malformed or missing truth.
CampaignTruth load_campaign_truth(const std::filesystem::path& truth_json);

}  // namespace scanbench::acquisition::sim
