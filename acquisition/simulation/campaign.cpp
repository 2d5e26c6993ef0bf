#include "acquisition/simulation/campaign.hpp"

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "acquisition/formats/output_file.hpp"
#include "acquisition/formats/ptx_writer.hpp"
#include "acquisition/formats/triplet_writer.hpp"
#include "acquisition/rigid_transform.hpp"
#include "acquisition/simulation/pose_error.hpp"
#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/truth_images.hpp"
#include "core/errors.hpp"
#include "core/timing.hpp"

namespace scanbench::acquisition::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TruthFiles truth_files(const fs::path& dir, const std::string& scan_name) {
  const fs::path base = dir / "truth";
  return {base / (scan_name + "_object_id.png"), base / (scan_name + "_normal.tiff"),
          base / (scan_name + "_range.tiff"), base / (scan_name + "_mixed.png")};
}

json vector_json(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

json lighting_json(const ScanLighting& l) {
  return {{"sun_direction_world", vector_json(l.sun_direction_world)},
          {"sun_irradiance", l.sun_irradiance},
          {"sky_irradiance", l.sky_irradiance},
          {"exposure", l.exposure},
          {"white_balance", vector_json(l.white_balance.cast<double>())}};
}

json scanner_json(const ScannerModel& m) {
  return {{"name", m.name},
          {"rows", m.rows},
          {"columns", m.columns},
          {"elevation_min_deg", m.elevation_min_deg},
          {"elevation_max_deg", m.elevation_max_deg},
          {"min_range_m", m.min_range_m},
          {"max_range_m", m.max_range_m},
          {"shadows", m.shadows}};
}

json noise_json(const ScannerModel& m) {
  return {{"range_noise_m", m.range_noise.noise_m},
          {"range_noise_per_m", m.range_noise.noise_per_m},
          {"range_noise_per_m2", m.range_noise.noise_per_m2},
          {"mixed_pixel_probability", m.mixed_pixel_probability},
          {"discontinuity_min_gap_m", m.discontinuity_min_gap_m},
          {"discontinuity_relative_gap", m.discontinuity_relative_gap},
          {"intensity_noise", m.intensity_noise},
          {"intensity_reference_range_m", m.intensity_reference_range_m}};
}

json objects_json(const Scene& scene) {
  json objects = json::array();
  for (const ObjectInfo& o : scene.objects()) {
    objects.push_back({{"id", o.id}, {"name", o.name}, {"parent", o.parent}, {"kind", o.kind}});
  }
  return objects;
}

std::string relative_name(const fs::path& path, const fs::path& dir) {
  return path.lexically_relative(dir).generic_string();
}

// Writes one simulated scan in the requested formats; returns its JSON entry.
json write_scan(const SimulatedScan& sim, const Eigen::Isometry3d& true_pose,
                const CampaignSettings& settings, const fs::path& dir, const ScanLighting& lighting,
                CampaignResult& result) {
  const std::string& name = sim.scan.name;
  json files = json::object();
  if (settings.format != CampaignFormat::kTriplet) {
    const fs::path ptx = dir / (name + ".ptx");
    write_ptx(ptx, {&sim.scan, 1});
    result.scan_files.push_back(ptx);
    files["ptx"] = relative_name(ptx, dir);
  }
  if (settings.format != CampaignFormat::kPtx) {
    const fs::path sidecar = dir / (name + ".json");
    write_triplet(sim.scan, sidecar);
    result.scan_files.push_back(sidecar);
    files["triplet"] = relative_name(sidecar, dir);
  }
  const TruthFiles truth = truth_files(dir, name);
  write_truth_images(sim.truth, sim.scan.rows, sim.scan.columns, truth);
  std::size_t mixed = 0;
  for (const std::uint8_t m : sim.truth.mixed) mixed += m;
  return {{"name", name},
          {"files", files},
          {"T_world_scan", row_major(true_pose)},
          {"stored_T_world_scan", row_major(sim.scan.T_world_scan)},
          {"lighting", lighting_json(lighting)},
          {"truth",
           {{"object_id", relative_name(truth.object_id, dir)},
            {"normal", relative_name(truth.normal, dir)},
            {"range", relative_name(truth.range, dir)},
            {"mixed", relative_name(truth.mixed, dir)}}},
          {"valid_points", count_valid(sim.scan)},
          {"mixed_points", mixed}};
}

void write_json(const fs::path& path, const json& value) {
  OutputFile out(path);
  out.write(value.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
  out.commit();
}

std::string scan_name(const std::string& site, int k) {
  char number[16];
  std::snprintf(number, sizeof number, "%02d", k + 1);
  return site + "_scan_" + number;
}

}  // namespace

CampaignResult simulate_campaign(const CampaignSettings& settings, const fs::path& out_dir,
                                 core::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  fs::create_directories(out_dir / "truth");
  const Site site = make_site(settings.site, settings.seed, settings.scans);
  CampaignResult result;
  json scans = json::array();
  for (int k = 0; k < static_cast<int>(site.scan_poses.size()); ++k) {
    progress.throw_if_cancelled("simulate");
    const std::uint64_t scan_seed = hash_combine(settings.seed, static_cast<std::uint64_t>(k) + 1);
    const ScanLighting lighting =
        settings.one_sun ? one_sun_lighting(scan_seed) : random_lighting(scan_seed);
    const auto cast_start = std::chrono::steady_clock::now();
    SimulatedScan sim = simulate_scan(site.scene, site.scan_poses[k], settings.scanner, lighting,
                                      scan_seed, settings.simulation);
    result.simulate_seconds += core::seconds_since(cast_start);
    sim.scan.name = scan_name(settings.site, k);
    const Eigen::Isometry3d true_pose = sim.scan.T_world_scan;
    if (k > 0 && (settings.pose_error_deg > 0.0 || settings.pose_error_m > 0.0)) {
      Random random(hash_combine(scan_seed, 0x504f5345u));  // "POSE"
      sim.scan.T_world_scan =
          true_pose * random_pose_error(settings.pose_error_deg, settings.pose_error_m, random);
      sim.scan.scanner.position_world = sim.scan.T_world_scan.translation();
    }
    scans.push_back(write_scan(sim, true_pose, settings, out_dir, lighting, result));
    progress.update({"simulate", static_cast<std::size_t>(k) + 1, site.scan_poses.size(),
                     scan_name(settings.site, k)});
  }
  result.truth_json = out_dir / "truth.json";
  write_json(result.truth_json, {{"format", "scanbench-truth"},
                                 {"version", 1},
                                 {"site", settings.site},
                                 {"seed", settings.seed},
                                 {"scanner", scanner_json(settings.scanner)},
                                 {"noise", noise_json(settings.scanner)},
                                 {"scans", scans},
                                 {"objects", objects_json(site.scene)}});
  result.total_seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::acquisition::sim
