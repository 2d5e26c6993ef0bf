// scanbench import PROJECT FILE...
#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/progress_bar.hpp"
#include "core/errors.hpp"
#include "modeling/import_command.hpp"

namespace scanbench::app {
namespace {

struct ImportOptions {
  std::string project;
  std::vector<std::string> files;
  modeling::ImportSettings settings;
};

void run_import(const ImportOptions& options) {
  const std::vector<std::filesystem::path> files(options.files.begin(), options.files.end());
  ProgressBar progress;
  const modeling::ImportResult result =
      modeling::import_scan_files(options.project, files, options.settings, progress);
  fmt::print("{} {} scan(s) from {} file(s) into {} in {:.2f} s\n",
             result.created_project ? "created project; imported" : "imported",
             result.scan_ids.size(), files.size(), options.project, result.seconds);
  if (result.images > 0) fmt::print("  {} image(s) stored with the scans\n", result.images);
  if (result.unplaced_points > 0) {
    fmt::print(
        "  {} record(s) not placed in the scan grids (later returns, or records repeating a "
        "pixel of a structured scan): those with a return are kept beside their grids as "
        "scattered scans named SCAN-unplaced (see `scanbench info PROJECT`)\n",
        result.unplaced_points);
  }
  for (const modeling::ImportResult::RoundTrip& r : result.beyond_promise) {
    fmt::print(
        "  warning: {} (scan \"{}\"): points come back up to {:.2f} mm from their values in the "
        "file, beyond 0.1 mm (a cloud spread too far for float ranges, or loosened settings)\n",
        core::one_line(r.file.string(), core::kMaxMessagePart),
        core::one_line(r.scan, core::kMaxMessagePart), 1e3 * r.error_m);
  }
}

}  // namespace

void add_import_command(CLI::App& app) {
  auto options = std::make_shared<ImportOptions>();
  CLI::App* command = app.add_subcommand(
      "import",
      "Import raw scans (Leica .ptx, ASTM E57 .e57, image-triplet .json sidecars, .pcd, and the "
      "unstructured clouds of .las and .ply, kept whole) into a project, creating it when "
      "missing. All files of one call go in one transaction: "
      "on any error the project is left unchanged.");
  command->add_option("project", options->project, "Project file (.sbproj)")->required();
  command->add_option("files", options->files, "Scan files")->required()->check(CLI::ExistingFile);
  command->add_flag("--allow-duplicate", options->settings.allow_duplicates,
                    "Import a scan even when the project already holds the same data (by "
                    "default that is refused: a file imported twice by mistake)");
  command->callback([options] { run_import(*options); });
}

}  // namespace scanbench::app
