// The campaign: the campus scanned under one sun, each scan with its own
// exposure and white balance (SiteLighting::kExposureOnly), at the true
// poses. The fit takes colour pairs on even rows and columns; the figures
// are measured on pairs from odd rows and columns, which the fit never saw.
// The truth colour of a point is what the same scan (same seed: same
// geometry and noise) records under the first scan's exposure and white
// balance: the albedo as the fixed scan renders it, the colour harmonising
// should reach.
#include "bench/bench_color.hpp"

#include <algorithm>
#include <chrono>

#include "acquisition/color_space.hpp"
#include "acquisition/simulation/sites.hpp"
#include "bench/simulated_site.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"
#include "registration/color_harmonization.hpp"

namespace scanbench::bench {

namespace {

namespace sim = acquisition::sim;

struct Campaign {
  SimulatedSite site;
  std::vector<registration::PreparedScan> prepared;
  std::vector<registration::ColorPair> fit;
  std::vector<registration::ColorPair> held_out;
  // Held out as well, but textured and edge points too: their colours
  // differ through the scans' footprints whatever the correction.
  std::vector<registration::ColorPair> held_out_all;
};

Campaign scan_campaign(const sim::ScannerModel& scanner, int scan_count, SiteLighting lighting) {
  Campaign c;
  c.site = simulate_site("campus", scanner, scan_count, lighting);
  for (std::size_t k = 0; k < c.site.scans.size(); ++k)
    c.prepared.push_back(registration::prepare_scan(c.site.scans[k], c.site.geometry[k], 0));
  // As many pairs per pair of scans as `scanbench harmonize` takes: round
  // the campus every scan overlaps every other.
  registration::ColorPairSettings fit;
  const std::size_t partners = c.site.scans.size() - 1;
  fit.max_pairs_per_overlap = registration::link_pair_budget(fit, partners, partners);
  c.fit = registration::find_color_pairs(c.prepared, c.site.true_poses, fit);
  registration::ColorPairSettings held_out = fit;
  held_out.phase = 1;
  held_out.max_pairs_per_overlap = 0;
  c.held_out = registration::find_color_pairs(c.prepared, c.site.true_poses, held_out);
  held_out.max_local_step = 255;
  c.held_out_all = registration::find_color_pairs(c.prepared, c.site.true_poses, held_out);
  return c;
}

// Mean ΔE of both points of every pair from their truth colours.
double delta_e_to_truth(std::span<const registration::ColorPair> pairs,
                        std::span<const store::ScanColorCorrection> corrections,
                        const std::vector<std::vector<std::uint8_t>>& truth_rgb) {
  if (pairs.empty()) return 0.0;
  const auto one = [&](std::uint32_t scan, std::int64_t pixel, const Eigen::Vector3f& rgb) {
    Eigen::Vector3d linear = rgb.cast<double>();
    if (!corrections.empty()) linear = corrections[scan].apply(linear).cwiseMax(0.0);
    const auto i = static_cast<std::size_t>(pixel);
    const std::vector<std::uint8_t>& t = truth_rgb[scan];
    return acquisition::delta_e(acquisition::linear_rgb_to_lab(linear),
                                acquisition::srgb_to_lab({t[3 * i], t[3 * i + 1], t[3 * i + 2]}));
  };
  double sum = 0.0;
  for (const registration::ColorPair& p : pairs)
    sum += one(p.scan_a, p.pixel_a, p.rgb_a) + one(p.scan_b, p.pixel_b, p.rgb_b);
  return sum / (2.0 * static_cast<double>(pairs.size()));
}

// The gains that take scan k's exposure and white balance to the first
// scan's: what a gain model should find where only those differ.
Eigen::Vector3d true_gain(SiteLighting lighting, int k) {
  const sim::ScanLighting first = scan_lighting(lighting, 0);
  const sim::ScanLighting own = scan_lighting(lighting, k);
  Eigen::Vector3d gain;
  for (int c = 0; c < 3; ++c)
    gain[c] = (first.exposure * first.white_balance[c]) / (own.exposure * own.white_balance[c]);
  return gain;
}

// Per scan, the largest relative error of a found gain against true_gain.
nlohmann::json gain_errors(const nlohmann::json& measured, SiteLighting lighting) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < measured["scans"].size(); ++k) {
    const Eigen::Vector3d truth = true_gain(lighting, static_cast<int>(k));
    double worst = 0.0;
    for (std::size_t c = 0; c < 3; ++c) {
      const double found = measured["scans"][k]["gains"][c];
      worst = std::max(worst, std::abs(found / truth[static_cast<int>(c)] - 1.0));
    }
    out.push_back(worst);
  }
  return out;
}

nlohmann::json solve_and_measure(const Campaign& c, registration::ColorModel model,
                                 const std::vector<std::vector<std::uint8_t>>* truth_rgb) {
  registration::HarmonizeSettings settings;
  settings.model = model;
  const auto start = std::chrono::steady_clock::now();
  const registration::HarmonizeResult solved =
      registration::harmonize_colors(c.fit, c.site.scans.size(), settings);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<store::ScanColorCorrection>& corrections = solved.corrections;
  const double before = modeling::mean_pair_delta_e(c.held_out, {});
  const double after = modeling::mean_pair_delta_e(c.held_out, corrections);
  nlohmann::json out = {
      {"before_delta_e", before},
      {"after_delta_e", after},
      {"reduction", before > 0.0 ? 1.0 - after / before : 0.0},
      {"solve_seconds", seconds},
      {"all_points_before_delta_e", modeling::mean_pair_delta_e(c.held_out_all, {})},
      {"all_points_after_delta_e", modeling::mean_pair_delta_e(c.held_out_all, corrections)},
      {"iterations", solved.iterations},
      {"converged", solved.converged}};
  if (truth_rgb) {
    out["before_delta_e_to_albedo"] = delta_e_to_truth(c.held_out, {}, *truth_rgb);
    out["after_delta_e_to_albedo"] = delta_e_to_truth(c.held_out, corrections, *truth_rgb);
  }
  nlohmann::json scans = nlohmann::json::array();
  for (const store::ScanColorCorrection& k : corrections) {
    scans.push_back({{"gains", {k.matrix(0, 0), k.matrix(1, 1), k.matrix(2, 2)}},
                     {"offsets", {k.offset.x(), k.offset.y(), k.offset.z()}}});
  }
  out["scans"] = scans;
  return out;
}

// Every scan again under the first scan's lighting: the truth colours.
std::vector<std::vector<std::uint8_t>> truth_colors(const sim::ScannerModel& scanner,
                                                    int scan_count) {
  const sim::Site site = sim::make_site("campus", kSiteSeed, scan_count);
  const sim::ScanLighting first = scan_lighting(SiteLighting::kExposureOnly, 0);
  std::vector<std::vector<std::uint8_t>> out;
  for (int k = 0; k < scan_count; ++k) {
    out.push_back(sim::simulate_scan(site.scene, site.scan_poses[static_cast<std::size_t>(k)],
                                     scanner, first, scan_seed(k))
                      .scan.rgb);
  }
  return out;
}

// The figures under the gains the simulator applied: the floor any
// per-scan correction can reach on these pairs (texture seen through other
// footprints, noise, shadow edges remain).
nlohmann::json under_true_gains(const Campaign& campaign,
                                const std::vector<std::vector<std::uint8_t>>& truth_rgb) {
  std::vector<store::ScanColorCorrection> true_gains;
  for (std::size_t k = 0; k < campaign.site.scans.size(); ++k) {
    store::ScanColorCorrection c;
    c.matrix.diagonal() = true_gain(SiteLighting::kExposureOnly, static_cast<int>(k));
    true_gains.push_back(c);
  }
  return {{"after_delta_e", modeling::mean_pair_delta_e(campaign.held_out, true_gains)},
          {"after_delta_e_to_albedo", delta_e_to_truth(campaign.held_out, true_gains, truth_rgb)}};
}

}  // namespace

nlohmann::json run_color_bench(const BenchOptions& options) {
  sim::ScannerModel scanner;
  scanner.columns = options.smoke ? 900 : 1800;
  scanner.rows = options.smoke ? 225 : 450;
  const int scan_count = options.smoke ? 2 : 4;

  const auto start = std::chrono::steady_clock::now();
  const Campaign campaign = scan_campaign(scanner, scan_count, SiteLighting::kExposureOnly);
  const std::vector<std::vector<std::uint8_t>> truth_rgb = truth_colors(scanner, scan_count);
  const double simulate_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  nlohmann::json gain_offset =
      solve_and_measure(campaign, registration::ColorModel::kGainOffset, &truth_rgb);
  const nlohmann::json matrix =
      solve_and_measure(campaign, registration::ColorModel::kMatrix, &truth_rgb);
  const nlohmann::json errors = gain_errors(gain_offset, SiteLighting::kExposureOnly);
  const double worst_gain_error = *std::max_element(errors.begin(), errors.end());
  const nlohmann::json floor = under_true_gains(campaign, truth_rgb);

  nlohmann::json out = {{"suite", "color"},
                        {"site", "campus"},
                        {"scans", scan_count},
                        {"scan_size", {scanner.columns, scanner.rows}},
                        {"lighting", "one sun; exposure and white balance per scan"},
                        {"fit_pairs", campaign.fit.size()},
                        {"held_out_pairs", campaign.held_out.size()},
                        {"simulate_seconds", simulate_seconds},
                        {"before_delta_e", gain_offset["before_delta_e"]},
                        {"after_delta_e", gain_offset["after_delta_e"]},
                        {"after_delta_e_to_albedo", gain_offset["after_delta_e_to_albedo"]},
                        {"reduction", gain_offset["reduction"]},
                        {"gain_relative_error_max", worst_gain_error},
                        {"true_gains", floor},
                        {"gain_offset", gain_offset},
                        {"matrix", matrix}};
  if (!options.smoke) {
    // The harder case: each scan its own sun too. No per-scan correction
    // can undo shading that differs per surface; this measures how much of
    // the difference is exposure and white balance.
    const Campaign suns = scan_campaign(scanner, scan_count, SiteLighting::kPerScan);
    nlohmann::json suns_gain_offset =
        solve_and_measure(suns, registration::ColorModel::kGainOffset, nullptr);
    suns_gain_offset["gain_relative_error"] = gain_errors(suns_gain_offset, SiteLighting::kPerScan);
    out["different_suns"] = {
        {"gain_offset", suns_gain_offset},
        {"matrix", solve_and_measure(suns, registration::ColorModel::kMatrix, nullptr)}};
  }
  out["goals"] = {{"reduction_at_least_0_8", out["reduction"].get<double>() >= 0.8}};
  return out;
}

}  // namespace scanbench::bench
