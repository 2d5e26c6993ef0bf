// scanbench simulate: the virtual scanner on a procedural site.
//   simulate --site S --out DIR [--scans N] [--columns C --rows R] [--seed K] [--format F]
//            [--noise P] [--pose-error-deg D --pose-error-m M] [--one-sun]
//   simulate --site S [--seed K] --render-view VIEW.json -o truth.png
#include <fmt/core.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "acquisition/simulation/campaign.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/truth_view.hpp"
#include "app/commands.hpp"
#include "app/progress_bar.hpp"

namespace scanbench::app {
namespace {

namespace sim = acquisition::sim;

struct SimulateOptions {
  sim::CampaignSettings campaign;
  sim::NoiseProfile noise = sim::NoiseProfile::kPulsed;
  std::string out_dir;
  std::string render_view;
  std::string output_png;
};

void run_campaign(SimulateOptions& options) {
  if (options.out_dir.empty())
    throw CLI::ValidationError("--out", "is required (the output folder)");
  const int most = sim::max_scan_count(options.campaign.site);
  if (options.campaign.scans > most) {
    throw CLI::ValidationError(
        "--scans", fmt::format("the {} site takes at most {} scans", options.campaign.site, most));
  }
  options.campaign.scanner = sim::with_noise_profile(options.campaign.scanner, options.noise);
  ProgressBar progress;
  const sim::CampaignResult result =
      sim::simulate_campaign(options.campaign, options.out_dir, progress);
  fmt::print("simulated {} scan(s) of {} (seed {}, {} x {}) in {:.1f} s ({:.1f} s ray casting)\n",
             options.campaign.scans, options.campaign.site, options.campaign.seed,
             options.campaign.scanner.rows, options.campaign.scanner.columns, result.total_seconds,
             result.simulate_seconds);
  for (const auto& file : result.scan_files) fmt::print("  scan  {}\n", file.string());
  fmt::print("  truth {}\n", result.truth_json.string());
}

void run_render_view(const SimulateOptions& options) {
  if (options.output_png.empty())
    throw CLI::ValidationError("-o", "is required with --render-view");
  if (std::filesystem::path(options.output_png).extension() != ".png")
    throw CLI::ValidationError("-o", "must name a .png file (the truth picture is a PNG)");
  const sim::CameraView view = sim::read_camera_view(options.render_view);
  const sim::Site site = sim::make_site(options.campaign.site, options.campaign.seed, 1);
  const sim::TruthImage image =
      sim::render_truth_view(site.scene, view, options.campaign.simulation);
  sim::write_truth_image(image, options.output_png);
  fmt::print("rendered {} x {} truth view of {} to {}\n", view.width, view.height,
             options.campaign.site, options.output_png);
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* command = app.add_subcommand(
      "simulate",
      "Scan a procedural site with the virtual panoramic scanner and write the scans with their "
      "exact ground truth, or ray-cast a ground-truth picture of the site (--render-view).");
  sim::CampaignSettings& campaign = options->campaign;
  command->add_option("--site", campaign.site, "Site")
      ->required()
      ->check(CLI::IsMember(sim::site_names()));
  command->add_option("--out", options->out_dir, "Output folder for scans and truth");
  command
      ->add_option("--scans", campaign.scans,
                   "Scan positions (campus and street: up to 64; path: up to 512, a street "
                   "that grows with the campaign)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--columns", campaign.scanner.columns, "Azimuth samples over 360°")
      ->check(CLI::Range(8, 36000))
      ->capture_default_str();
  command->add_option("--rows", campaign.scanner.rows, "Elevation samples over the window")
      ->check(CLI::Range(4, 18000))
      ->capture_default_str();
  command->add_option("--seed", campaign.seed, "Seed: the same seed gives byte-identical output")
      ->capture_default_str();
  const std::map<std::string, sim::CampaignFormat> formats{
      {"ptx", sim::CampaignFormat::kPtx},
      {"triplet", sim::CampaignFormat::kTriplet},
      {"both", sim::CampaignFormat::kBoth}};
  command->add_option("--format", campaign.format, "ptx, triplet or both (default triplet)")
      ->transform(one_of(formats));
  std::map<std::string, sim::NoiseProfile> profiles;
  for (const sim::NoiseProfile profile : sim::kNoiseProfiles)
    profiles[sim::noise_profile_name(profile)] = profile;
  command
      ->add_option("--noise", options->noise,
                   "Range noise of: pulsed (default; σ = 5 mm + 5e-5 r, 1–200 m), phase-shift "
                   "(σ = 0.6 mm + 2e-5 r + 2e-6 r², 0.6–120 m) or structured-light (σ = 1.5e-3 "
                   "r², 0.5–8 m)")
      ->transform(one_of(profiles));
  command->add_flag("--one-sun", campaign.one_sun,
                    "Light every scan by one sun: the scans' colours then differ by exposure "
                    "and white balance only (truth.json has each scan's)");
  add_threads_option(command, campaign.simulation.threads);
  command
      ->add_option("--pose-error-deg", campaign.pose_error_deg,
                   "Rotation error written into the files of scans 2.. (truth keeps true poses)")
      ->check(CLI::Range(0.0, 180.0));
  command
      ->add_option("--pose-error-m", campaign.pose_error_m,
                   "Translation error written into the files of scans 2.. [m]")
      ->check(CLI::Range(0.0, 1000.0));
  command
      ->add_option("--render-view", options->render_view,
                   "Camera view JSON: render a truth picture")
      ->check(CLI::ExistingFile);
  command->add_option("-o,--output", options->output_png, "Truth picture (PNG) for --render-view");
  command->callback([options] {
    if (options->render_view.empty()) {
      run_campaign(*options);
    } else {
      run_render_view(*options);
    }
  });
}

}  // namespace scanbench::app
