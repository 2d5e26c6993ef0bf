// scanbench register PROJECT [--coarse features|pairs|none] [--pairs FILE] [--unlevelled]
//                            [--no-global] [--settings FILE] [--threads N]
//                            [--memory-limit SIZE] [--json]
#include <fmt/core.h>

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.hpp"
#include "app/formats/point_pairs_file.hpp"
#include "app/progress_bar.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"

namespace scanbench::app {
namespace {

struct RegisterOptions {
  std::string project;
  registration::CoarseMethod coarse = registration::CoarseMethod::kFeatures;
  std::string pairs_file;
  bool unlevelled = false;
  bool no_global = false;
  std::string settings_file;
  int threads = 0;
  bool json = false;
  std::uint64_t memory_limit = 0;
};

void print_table(const modeling::RegisterCommandResult& out) {
  const registration::RegistrationResult& r = out.result;
  fmt::print("{:>6} {:>6}  {:<10} {:<8} {:>9} {:>8} {:>8} {:>5}  {}\n", "source", "target",
             "coarse", "start", "rms [mm]", "overlap", "inliers", "iter", "result");
  for (const registration::PairReport& p : r.pairs) {
    fmt::print("{:>6} {:>6}  {:<10} {:<8} {:>9.2f} {:>8.3f} {:>8} {:>5}  {}\n",
               out.ids[static_cast<std::size_t>(p.source)],
               out.ids[static_cast<std::size_t>(p.target)],
               p.coarse.success ? registration::coarse_method_name(p.coarse.method) : "failed",
               registration::icp_start_name(p.start), 1000.0 * p.icp.rms_m, p.icp.overlap,
               p.icp.correspondences, p.icp.iterations,
               p.registered ? "registered" : "FAILED: " + p.failure);
  }
  fmt::print("global refinement: {} rounds, {}; {} overlapping pairs\n", r.global.rounds,
             r.global.converged ? "converged" : "not converged", r.edges.size());
  fmt::print("overall: rms {:.2f} mm, overlap {:.3f}, {} inliers, {} iterations, {} ({:.2f} s)\n",
             1000.0 * r.rms_m, r.overlap, r.correspondences, r.iterations,
             r.converged ? "converged" : "NOT converged", r.seconds);
}

// The settings the options give.
modeling::RegisterCommandSettings settings_of(const RegisterOptions& options) {
  modeling::RegisterCommandSettings settings;
  registration::RegistrationSettings& s = settings.registration;
  s.coarse = options.coarse;
  if (!options.pairs_file.empty()) {
    s.coarse = registration::CoarseMethod::kPointPairs;
    settings.picks = read_point_pairs_file(options.pairs_file);
  } else if (s.coarse == registration::CoarseMethod::kPointPairs) {
    throw CLI::ValidationError("--coarse pairs", "needs --pairs FILE");
  }
  if (options.unlevelled && s.coarse != registration::CoarseMethod::kFeatures) {
    throw CLI::ValidationError("--unlevelled", "applies to --coarse features only");
  }
  s.features.levelled = !options.unlevelled;
  s.refine_globally = !options.no_global;
  return settings;
}

void run_register(const RegisterOptions& options) {
  modeling::RegisterCommandSettings settings =
      options.settings_file.empty()
          ? settings_of(options)
          : read_settings_file<modeling::RegisterCommandSettings>(options.settings_file);
  registration::RegistrationSettings& s = settings.registration;
  s.icp.threads = s.features.threads = s.global.icp.threads = options.threads;
  store::Project project = store::Project::open(options.project);
  ProgressBar progress;
  const modeling::RegisterCommandResult out = modeling::register_project(
      project, settings, progress, memory_limit_of(options.memory_limit));
  if (options.json) {
    fmt::print("{}\n", modeling::result_json(out));
  } else {
    print_table(out);
  }
}

}  // namespace

void add_register_command(CLI::App& app) {
  auto options = std::make_shared<RegisterOptions>();
  CLI::App* command = app.add_subcommand(
      "register",
      "Align every scan of the project to the first: coarse (features or picked point pairs), "
      "point-to-plane ICP, then a global refinement over all overlapping pairs. Stores the poses "
      "and the report (one command, undoable); merge keep masks become stale and are dropped.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  const std::map<std::string, registration::CoarseMethod> coarse_methods{
      {"features", registration::CoarseMethod::kFeatures},
      {"pairs", registration::CoarseMethod::kPointPairs},
      {"point_pairs", registration::CoarseMethod::kPointPairs},
      {"none", registration::CoarseMethod::kNone}};
  CLI::Option* settings = add_settings_option(command, options->settings_file);
  command
      ->add_option("--coarse", options->coarse, "Coarse stage: features (default), pairs or none")
      ->transform(one_of(coarse_methods))
      ->excludes(settings);
  command
      ->add_option("--pairs", options->pairs_file,
                   "Picked point pairs (JSON, see docs/registration.md); implies --coarse pairs")
      ->check(CLI::ExistingFile)
      ->excludes(settings);
  command
      ->add_flag("--unlevelled", options->unlevelled,
                 "The scanner was not levelled on site: feature poses from three matches each "
                 "instead of one")
      ->excludes(settings);
  command->add_flag("--no-global", options->no_global, "Skip the global refinement")
      ->excludes(settings);
  add_threads_option(command, options->threads);
  add_memory_limit_option(command, options->memory_limit);
  command->add_flag("--json", options->json, "Print the report as one JSON object");
  command->callback([options] { run_register(*options); });
}

}  // namespace scanbench::app
