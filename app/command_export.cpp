// scanbench export PROJECT --format ptx|ply|csv|las|e57|triplet [--scan ID] [--merged]
//   [--colors shown|recorded] [--all] [--force] -o OUT
#include <fmt/core.h>

#include <map>
#include <memory>
#include <string>

#include "app/commands.hpp"
#include "app/progress_bar.hpp"
#include "modeling/export_command.hpp"

namespace scanbench::app {
namespace {

struct ExportOptions {
  std::string project;
  std::optional<std::int64_t> scan_id;
  modeling::ExportSettings settings;
  std::string output;
};

void run_export(ExportOptions& options) {
  options.settings.scan_id = options.scan_id;
  options.settings.output = options.output;
  const store::Project project = store::Project::open_for_reading(options.project);
  const modeling::ExportResult result = [&] {
    ProgressBar progress;  // its line ends before the summary
    return modeling::export_project(project, options.settings, &progress);
  }();
  fmt::print("exported {} scan(s), {} {} points, to {}\n", result.scans, result.points,
             options.settings.merged ? "merged-model" : "valid", options.output);
  if (result.hidden + result.deleted > 0) {
    fmt::print("left out {} points of hidden objects and {} deleted points (--all writes them)\n",
               result.hidden, result.deleted);
  }
  for (const std::string& note : result.notes) fmt::print("note: {}\n", note);
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* command = app.add_subcommand(
      "export",
      "Export scans: PTX (scan frame + pose, lossless), binary PLY or CSV (valid points in world "
      "coordinates, double precision; after `scanbench geometry`, without mixed pixels and, in "
      "PLY, with normals and footprints), LAS 1.4 (point format 7, world coordinates at 0.1 mm, "
      "the scan id as point source id; normals and footprints as extra bytes), ASTM E57 "
      "(structured scans in spherical coordinates at 0.1 mm with their poses and images), or an "
      "image triplet (one scan).");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  const std::map<std::string, modeling::ExportFormat> formats{
      {"ptx", modeling::ExportFormat::kPtx}, {"ply", modeling::ExportFormat::kPly},
      {"csv", modeling::ExportFormat::kCsv}, {"triplet", modeling::ExportFormat::kTriplet},
      {"las", modeling::ExportFormat::kLas}, {"e57", modeling::ExportFormat::kE57}};
  command->add_option("--format", options->settings.format, "ptx, ply, csv, las, e57 or triplet")
      ->required()
      ->transform(one_of(formats));
  command->add_option("--scan", options->scan_id, "Export only the scan with this id");
  command->add_flag("--merged", options->settings.merged,
                    "The merged model only: the points `scanbench merge` kept (PLY, CSV, LAS; in "
                    "E57 the other pixels are marked invalid)");
  const std::map<std::string, modeling::ExportColors> colors{
      {"shown", modeling::ExportColors::kShown}, {"recorded", modeling::ExportColors::kRecorded}};
  command
      ->add_option("--colors", options->settings.colors,
                   "shown (default: as the model shows them, with the harmonisation and the "
                   "objects' colour edits) or recorded (as the scanner recorded them)")
      ->transform(one_of(colors));
  command->add_flag("--all", options->settings.all_points,
                    "Every point: also those of hidden objects and the deleted ones (by default "
                    "the export holds what the model shows; grid formats mark the others "
                    "invalid)");
  command->add_option("-o,--output", options->output, "Output file (triplet: the .json sidecar)")
      ->required();
  command->add_flag("--force", options->settings.replace_existing,
                    "Replace the output when it exists (never the project, nor a file its scans "
                    "were imported from)");
  command->callback([options] { run_export(*options); });
}

}  // namespace scanbench::app
