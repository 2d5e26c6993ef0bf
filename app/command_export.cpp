// scanbench export PROJECT --format ptx|ply|csv|triplet [--scan ID] [--merged] -o OUT
#include <fmt/core.h>

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/point_export.hpp"
#include "acquisition/ptx_writer.hpp"
#include "acquisition/triplet_writer.hpp"
#include "app/commands.hpp"
#include "core/errors.hpp"
#include "modeling/project.hpp"

namespace scanbench::app {
namespace {

enum class ExportFormat { kPtx, kPly, kCsv, kTriplet };

struct ExportOptions {
  std::string project;
  ExportFormat format = ExportFormat::kPtx;
  std::optional<std::int64_t> scan_id;
  bool merged = false;
  std::string output;
};

std::vector<acquisition::Scan> load_scans(const modeling::Project& project,
                                          std::optional<std::int64_t> scan_id) {
  std::vector<acquisition::Scan> scans;
  if (scan_id) {
    scans.push_back(project.load_scan(*scan_id));
    return scans;
  }
  for (const auto& stored : project.scans()) scans.push_back(project.load_scan(stored.id));
  return scans;
}

// The stored geometry of each scan (nullptr where `scanbench geometry` has
// not run), for the exports that leave mixed pixels out and carry normals.
std::vector<std::optional<acquisition::ScanGeometry>> load_geometry(
    const modeling::Project& project, std::optional<std::int64_t> scan_id) {
  std::vector<std::optional<acquisition::ScanGeometry>> geometry;
  if (scan_id) {
    geometry.push_back(project.load_geometry(*scan_id));
    return geometry;
  }
  for (const auto& stored : project.scans()) geometry.push_back(project.load_geometry(stored.id));
  return geometry;
}

// With --merged, the keep mask of every exported scan (`scanbench merge`);
// none otherwise. Throws InputError naming the project when a scan has none
// or the format is a scan-grid format.
std::vector<std::vector<std::uint8_t>> load_keep_masks(const ExportOptions& options,
                                                       const modeling::Project& project) {
  if (!options.merged) return {};
  if (options.format != ExportFormat::kPly && options.format != ExportFormat::kCsv) {
    throw core::InputError(options.project, {},
                           "--merged writes a point list: use --format ply or csv");
  }
  std::vector<std::vector<std::uint8_t>> masks;
  for (const auto& stored : project.scans()) {
    if (options.scan_id && stored.id != *options.scan_id) continue;
    std::optional<std::vector<std::uint8_t>> mask = project.load_keep_mask(stored.id);
    if (!mask) {
      throw core::InputError(
          options.project, {0, 0, "scan " + std::to_string(stored.id)},
          "no merged model for this scan: run `scanbench merge` after the last registration");
    }
    masks.push_back(std::move(*mask));
  }
  return masks;
}

void write_scans(const ExportOptions& options, const std::vector<acquisition::Scan>& scans,
                 const std::vector<std::optional<acquisition::ScanGeometry>>& geometry,
                 const std::vector<std::vector<std::uint8_t>>& keep) {
  std::vector<const acquisition::ScanGeometry*> pointers;
  for (const auto& g : geometry) pointers.push_back(g ? &*g : nullptr);
  std::vector<const std::vector<std::uint8_t>*> masks;
  for (const auto& mask : keep) masks.push_back(&mask);
  switch (options.format) {
    case ExportFormat::kPtx:
      return acquisition::write_ptx(options.output, scans);
    case ExportFormat::kPly:
      return acquisition::write_ply(options.output, scans, pointers, masks);
    case ExportFormat::kCsv:
      return acquisition::write_csv(options.output, scans, pointers, masks);
    case ExportFormat::kTriplet:
      if (scans.size() != 1) {
        throw core::InputError(options.project, {},
                               "a triplet holds one scan: choose it with --scan ID");
      }
      if (!scans.front().is_spherical()) {
        throw core::InputError(options.project, {0, 0, "scan \"" + scans.front().name + "\""},
                               "a triplet needs the spherical angle model; this scan has "
                               "per-pixel directions (export it as ptx, ply or csv)");
      }
      return acquisition::write_triplet(scans.front(), options.output);
  }
}

void run_export(const ExportOptions& options) {
  const modeling::Project project = modeling::Project::open(options.project);
  const std::vector<std::vector<std::uint8_t>> keep = load_keep_masks(options, project);
  const std::vector<acquisition::Scan> scans = load_scans(project, options.scan_id);
  write_scans(options, scans, load_geometry(project, options.scan_id), keep);
  std::size_t points = 0;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    if (keep.empty()) {
      points += acquisition::count_valid(scans[s]);
      continue;
    }
    for (std::size_t i = 0; i < keep[s].size(); ++i) points += keep[s][i] != 0 ? 1 : 0;
  }
  fmt::print("exported {} scan(s), {} {} points, to {}\n", scans.size(), points,
             keep.empty() ? "valid" : "merged-model", options.output);
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* command = app.add_subcommand(
      "export",
      "Export scans: PTX (scan frame + pose, lossless), binary PLY or CSV (valid points in world "
      "coordinates, double precision; after `scanbench geometry`, without mixed pixels and, in "
      "PLY, with normals and footprints), or an image triplet (one scan).");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  const std::map<std::string, ExportFormat> formats{{"ptx", ExportFormat::kPtx},
                                                    {"ply", ExportFormat::kPly},
                                                    {"csv", ExportFormat::kCsv},
                                                    {"triplet", ExportFormat::kTriplet}};
  command->add_option("--format", options->format, "ptx, ply, csv or triplet")
      ->required()
      ->transform(CLI::CheckedTransformer(formats, CLI::ignore_case));
  command->add_option("--scan", options->scan_id, "Export only the scan with this id");
  command->add_flag("--merged", options->merged,
                    "PLY or CSV of the merged model only: the points `scanbench merge` kept");
  command->add_option("-o,--output", options->output, "Output file (triplet: the .json sidecar)")
      ->required();
  command->callback([options] { run_export(*options); });
}

}  // namespace scanbench::app
