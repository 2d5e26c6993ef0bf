// scanbench info PROJECT|FILE [--json]
#include <fmt/core.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/formats/scan_files.hpp"
#include "acquisition/rigid_transform.hpp"
#include "acquisition/scan_summary.hpp"
#include "app/commands.hpp"
#include "core/errors.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::app {
namespace {

struct InfoOptions {
  std::string path;
  bool json = false;
};

struct Entry {
  std::int64_t id;
  acquisition::ScanSummary summary;
  std::optional<acquisition::ScanSource> source;  // none for scans imported before schema 7
};

// An image of the project or file, and the id of its scan.
struct ImageEntry {
  std::int64_t id;
  std::optional<std::int64_t> scan_id;
  acquisition::ScanImage image;  // without data
  std::size_t bytes = 0;         // of the encoded image
};

struct Contents {
  std::vector<Entry> scans;
  std::vector<ImageEntry> images;
};

Contents project_entries(const std::filesystem::path& path) {
  Contents contents;
  const store::Project project = store::Project::open_for_reading(path);
  const std::map<std::int64_t, acquisition::ScanSource> sources = project.scan_sources();
  for (auto& stored : project.scans()) {
    const auto source = sources.find(stored.id);
    contents.scans.push_back(
        {stored.id, std::move(stored.summary),
         source == sources.end() ? std::nullopt : std::optional(source->second)});
  }
  for (store::StoredImage& stored : project.images(true)) {
    const std::size_t bytes = stored.image.data.size();
    stored.image.data = {};
    contents.images.push_back({stored.id, stored.scan_id, std::move(stored.image), bytes});
  }
  return contents;
}

// A raw scan file: ids are 1-based positions in the file.
Contents file_entries(const std::filesystem::path& path) {
  Contents contents;
  const auto add_image = [&contents](acquisition::ScanImage&& image,
                                     std::optional<std::int64_t> scan_id) {
    const std::size_t bytes = image.data.size();
    image.data = {};
    contents.images.push_back(
        {static_cast<std::int64_t>(contents.images.size() + 1), scan_id, std::move(image), bytes});
  };
  acquisition::read_scan_file(
      path, {},
      [&](acquisition::ImportedScan&& imported) {
        const auto id = static_cast<std::int64_t>(contents.scans.size() + 1);
        contents.scans.push_back({id, acquisition::summarize(imported.scan), imported.source});
        for (acquisition::ScanImage& image : imported.images) add_image(std::move(image), id);
      },
      [&](acquisition::ScanImage&& image) { add_image(std::move(image), std::nullopt); });
  return contents;
}

nlohmann::json to_json(const ImageEntry& entry) {
  const acquisition::ScanImage& image = entry.image;
  return {{"id", entry.id},
          {"scan", entry.scan_id ? nlohmann::json(*entry.scan_id) : nlohmann::json(nullptr)},
          {"name", image.name},
          {"guid", image.guid},
          {"projection", acquisition::projection_name(image.projection)},
          {"format", image.format},
          {"width", image.width},
          {"height", image.height},
          {"pixel_width", image.pixel_width},
          {"pixel_height", image.pixel_height},
          {"focal_length", image.focal_length},
          {"principal_point", {image.principal_x, image.principal_y}},
          {"radius", image.radius},
          {"T_world_image", acquisition::row_major(image.T_world_image)},
          {"bytes", entry.bytes}};
}

nlohmann::json to_json(const Entry& entry) {
  const acquisition::ScanSummary& s = entry.summary;
  nlohmann::json bbox = nullptr;
  if (s.bbox_world) {
    const Eigen::Vector3d lo = s.bbox_world->min(), hi = s.bbox_world->max();
    bbox = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
  }
  return {{"id", entry.id},
          {"name", s.name},
          {"rows", s.rows},
          {"columns", s.columns},
          {"valid_points", s.valid_points},
          {"has_color", s.has_color},
          {"has_intensity", s.has_intensity},
          {"angle_model", acquisition::angle_model_name(s.spherical)},
          {"layout", s.scattered ? "scattered" : "grid"},
          {"T_world_scan", acquisition::row_major(s.T_world_scan)},
          {"bbox_world", bbox},
          {"scanner", s.scanner.name},
          {"source_file", s.scanner.source_file},
          {"source",
           entry.source ? nlohmann::json{{"format", entry.source->format},
                                         {"guid", entry.source->guid},
                                         {"coordinate_metadata", entry.source->coordinate_metadata},
                                         {"points_in_file", entry.source->points_in_file},
                                         {"unplaced_points", entry.source->unplaced_points},
                                         {"round_trip_error_m", entry.source->round_trip_error_m}}
                        : nlohmann::json(nullptr)}};
}

void print_table(const std::string& path, const Contents& contents) {
  fmt::print("{}: {} scan(s)\n", path, contents.scans.size());
  fmt::print("{:>4}  {:<24} {:>13} {:>10}  {:<5} {:<9} {:<9} {}\n", "id", "name", "rows x cols",
             "valid", "color", "intensity", "angles", "position [m]");
  for (const Entry& e : contents.scans) {
    const acquisition::ScanSummary& s = e.summary;
    const Eigen::Vector3d t = s.T_world_scan.translation();
    fmt::print("{:>4}  {:<24} {:>13} {:>10}  {:<5} {:<9} {:<9} {:.3f} {:.3f} {:.3f}\n", e.id,
               core::one_line(s.name, core::kMaxMessagePart),
               fmt::format("{} x {}", s.rows, s.columns), s.valid_points,
               s.has_color ? "yes" : "no", s.has_intensity ? "yes" : "no",
               s.scattered ? "scattered" : acquisition::angle_model_name(s.spherical), t.x(), t.y(),
               t.z());
    if (e.source && e.source->unplaced_points > 0) {
      fmt::print(
          "      {} of the file's {} records not placed in the grid (later returns, or "
          "records repeating a pixel): those with a return, if any, are the scan "
          "\"{}-unplaced\" (-unplaced-1, … when tiled)\n",
          e.source->unplaced_points, e.source->points_in_file,
          core::one_line(s.name, core::kMaxMessagePart));
    }
    if (e.source && e.source->round_trip_error_m > acquisition::kPromisedRoundTripM) {
      fmt::print("      points up to {:.2f} mm from their values in the file (beyond 0.1 mm)\n",
                 1e3 * e.source->round_trip_error_m);
    }
  }
  if (contents.images.empty()) return;
  fmt::print("{} image(s)\n", contents.images.size());
  for (const ImageEntry& i : contents.images) {
    fmt::print("{:>4}  {:<24} {:>13} {:<5} {:<11} scan {}\n", i.id, i.image.name,
               fmt::format("{} x {}", i.image.width, i.image.height), i.image.format,
               acquisition::projection_name(i.image.projection),
               i.scan_id ? std::to_string(*i.scan_id) : std::string("none"));
  }
}

bool starts_like_sqlite(const std::filesystem::path& path) {
  char header[16] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(header, sizeof header);
  return in.gcount() == sizeof header && std::memcmp(header, "SQLite format 3", 16) == 0;
}

void run_info(const InfoOptions& options) {
  const std::filesystem::path path = options.path;
  const bool project = path.extension() == ".sbproj" || starts_like_sqlite(path);
  const Contents contents = project ? project_entries(path) : file_entries(path);
  if (!options.json) {
    print_table(options.path, contents);
    return;
  }
  nlohmann::json scans = nlohmann::json::array();
  for (const Entry& e : contents.scans) scans.push_back(to_json(e));
  nlohmann::json images = nlohmann::json::array();
  for (const ImageEntry& i : contents.images) images.push_back(to_json(i));
  fmt::print("{}\n", nlohmann::json{{"scans", scans}, {"images", images}}.dump(
                         2, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand(
      "info",
      "Describe the scans and images of a project or of a raw scan file (.ptx, .e57, .json, "
      ".pcd, .ply, .las).");
  command->add_option("path", options->path, "Project (.sbproj) or scan file")
      ->required()
      ->check(CLI::ExistingPath);
  command->add_flag("--json", options->json, "Print JSON instead of a table");
  command->callback([options] { run_info(*options); });
}

}  // namespace scanbench::app
