// scanbench geometry PROJECT [--window R] [--edge-window R] [--no-mixed-pixels] [--fixed-noise]
//                            [--settings FILE] [--threads N]
#include <fmt/core.h>

#include <memory>
#include <string>

#include "app/commands.hpp"
#include "app/progress_bar.hpp"
#include "modeling/geometry_command.hpp"

namespace scanbench::app {
namespace {

struct GeometryOptions {
  std::string project;
  acquisition::GeometrySettings geometry;
  bool no_mixed_pixels = false;
  bool fixed_noise = false;
  std::string settings_file;
};

void run_geometry(GeometryOptions& options) {
  acquisition::GeometrySettings& g = options.geometry;
  if (!options.settings_file.empty()) {
    const int threads = g.threads;
    g = read_settings_file<acquisition::GeometrySettings>(options.settings_file);
    g.threads = threads;
  } else if (g.edge_window_radius > g.window_radius) {
    throw CLI::ValidationError("--edge-window", "must not exceed --window");
  } else {
    g.flag_mixed_pixels = !options.no_mixed_pixels;
    g.estimate_range_noise = !options.fixed_noise;
  }
  store::Project project = store::Project::open(options.project);
  ProgressBar progress;
  const modeling::GeometryCommandResult result =
      modeling::geometry_project(project, options.geometry, progress);
  fmt::print("{:>4}  {:<24} {:>10} {:>10} {:>8} {:>8}  {:<30} {:>8}\n", "id", "name", "valid",
             "normals", "mixed", "edges", "range noise σ at 1/10/50 m [mm]", "seconds");
  for (const modeling::GeometryCommandScan& s : result.scans) {
    const std::string noise =
        fmt::format("{:.2f} / {:.2f} / {:.2f}{}", 1e3 * s.range_noise.sigma(1.0),
                    1e3 * s.range_noise.sigma(10.0), 1e3 * s.range_noise.sigma(50.0),
                    s.noise_estimated ? " (estimated)" : "");
    fmt::print("{:>4}  {:<24} {:>10} {:>10} {:>8} {:>8}  {:<30} {:>8.3f}\n", s.id, s.name,
               s.valid_points, s.normals, s.mixed_pixels, s.edge_pixels, noise, s.seconds);
  }
  for (const modeling::GeometryCommandScan& s : result.scans) {
    if (s.recorded_normals > 0)
      fmt::print("scan {}: {} normals kept as its file recorded them\n", s.id, s.recorded_normals);
  }
  fmt::print("geometry of {} scan(s) stored in {} ({:.2f} s)\n", result.scans.size(),
             options.project, result.seconds);
}

}  // namespace

void add_geometry_command(CLI::App& app) {
  auto options = std::make_shared<GeometryOptions>();
  CLI::App* command = app.add_subcommand(
      "geometry",
      "Compute every scan's per-point footprint, normal (from its neighbours in the scan grid), "
      "confidence and mixed-pixel/edge flags, and store them in the project (one command, "
      "undoable).");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  acquisition::GeometrySettings& g = options->geometry;
  CLI::Option* settings = add_settings_option(command, options->settings_file);
  command->add_option("--window", g.window_radius, "Radius of the widest fitting window [pixels]")
      ->check(CLI::Range(1, acquisition::kMaxWindowRadius))
      ->capture_default_str()
      ->excludes(settings);
  command
      ->add_option("--edge-window", g.edge_window_radius,
                   "Radius of the window near edges [pixels]")
      ->check(CLI::Range(1, acquisition::kMaxWindowRadius))
      ->capture_default_str()
      ->excludes(settings);
  command->add_flag("--no-mixed-pixels", options->no_mixed_pixels, "Do not flag mixed pixels")
      ->excludes(settings);
  command
      ->add_flag("--fixed-noise", options->fixed_noise,
                 "Do not estimate each scan's range noise from its data; take the pulsed "
                 "scanner's (σ = 5 mm + 5e-5 · range) for every scan")
      ->excludes(settings);
  add_threads_option(command, g.threads);
  command->callback([options] { run_geometry(*options); });
}

}  // namespace scanbench::app
