// scanbench info PROJECT|FILE [--json]
#include <fmt/core.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "acquisition/rigid_transform.hpp"
#include "acquisition/scan_files.hpp"
#include "acquisition/scan_summary.hpp"
#include "app/commands.hpp"
#include "modeling/project.hpp"

namespace scanbench::app {
namespace {

struct InfoOptions {
  std::string path;
  bool json = false;
};

struct Entry {
  std::int64_t id;
  acquisition::ScanSummary summary;
};

std::vector<Entry> project_entries(const std::filesystem::path& path) {
  std::vector<Entry> entries;
  for (auto& stored : modeling::Project::open_for_reading(path).scans()) {
    entries.push_back({stored.id, std::move(stored.summary)});
  }
  return entries;
}

// A raw scan file: ids are 1-based positions in the file.
std::vector<Entry> file_entries(const std::filesystem::path& path) {
  std::vector<Entry> entries;
  acquisition::read_scan_file(path, {}, [&entries](acquisition::Scan&& scan) {
    entries.push_back(
        {static_cast<std::int64_t>(entries.size() + 1), acquisition::summarize(scan)});
  });
  return entries;
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
          {"T_world_scan", acquisition::row_major(s.T_world_scan)},
          {"bbox_world", bbox},
          {"scanner", s.scanner.name},
          {"source_file", s.scanner.source_file}};
}

void print_table(const std::string& path, const std::vector<Entry>& entries) {
  fmt::print("{}: {} scan(s)\n", path, entries.size());
  fmt::print("{:>4}  {:<24} {:>13} {:>10}  {:<5} {:<9} {:<9} {}\n", "id", "name", "rows x cols",
             "valid", "color", "intensity", "angles", "position [m]");
  for (const Entry& e : entries) {
    const acquisition::ScanSummary& s = e.summary;
    const Eigen::Vector3d t = s.T_world_scan.translation();
    fmt::print("{:>4}  {:<24} {:>13} {:>10}  {:<5} {:<9} {:<9} {:.3f} {:.3f} {:.3f}\n", e.id,
               s.name, fmt::format("{} x {}", s.rows, s.columns), s.valid_points,
               s.has_color ? "yes" : "no", s.has_intensity ? "yes" : "no",
               acquisition::angle_model_name(s.spherical), t.x(), t.y(), t.z());
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
  const std::vector<Entry> entries = project ? project_entries(path) : file_entries(path);
  if (!options.json) {
    print_table(options.path, entries);
    return;
  }
  nlohmann::json scans = nlohmann::json::array();
  for (const Entry& e : entries) scans.push_back(to_json(e));
  fmt::print("{}\n", nlohmann::json{{"scans", scans}}.dump(
                         2, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand(
      "info", "Describe the scans of a project or of a raw scan file (.ptx, .json, .pcd).");
  command->add_option("path", options->path, "Project (.sbproj) or scan file")
      ->required()
      ->check(CLI::ExistingPath);
  command->add_flag("--json", options->json, "Print JSON instead of a table");
  command->callback([options] { run_info(*options); });
}

}  // namespace scanbench::app
