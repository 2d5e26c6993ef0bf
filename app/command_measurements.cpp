// scanbench measurements PROJECT [--json] [--csv OUT [--force]]
#include <fmt/core.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "acquisition/formats/output_file.hpp"
#include "app/commands.hpp"
#include "core/errors.hpp"
#include "modeling/export_command.hpp"
#include "modeling/measurements.hpp"

namespace scanbench::app {
namespace {

struct MeasurementsOptions {
  std::string project;
  bool json = false;
  std::filesystem::path csv;
  bool force = false;
};

nlohmann::json to_json(const modeling::Measurement& m) {
  nlohmann::json points = nlohmann::json::array();
  for (const Eigen::Vector3d& p : m.points) points.push_back({p.x(), p.y(), p.z()});
  return {{"name", m.name},
          {"kind", modeling::measure_kind_name(m.kind)},
          {"value", modeling::measured_value(m)},
          {"unit", modeling::measured_unit(m.kind)},
          {"points", points}};
}

void run_measurements(const MeasurementsOptions& options) {
  const store::Project project = store::Project::open_for_reading(options.project);
  const std::vector<modeling::Measurement> list = modeling::load_measurements(project);
  if (!options.csv.empty()) {
    const std::filesystem::path outputs[] = {options.csv};
    modeling::refuse_to_replace_inputs(project, outputs, options.force);
    acquisition::OutputFile out(options.csv);
    out.write(modeling::measurements_csv(list));
    out.commit();
  }
  if (options.json) {
    nlohmann::json all = nlohmann::json::array();
    for (const modeling::Measurement& m : list) all.push_back(to_json(m));
    fmt::print("{}\n", nlohmann::json{{"measurements", all}}.dump(
                           2, ' ', false, nlohmann::json::error_handler_t::replace));
    return;
  }
  if (list.empty()) {
    fmt::print("{}: no measurements yet (the workbench takes them)\n", options.project);
    return;
  }
  fmt::print("{:<24} {:<9} {:>14}  {}\n", "name", "kind", "value", "unit");
  for (const modeling::Measurement& m : list) {
    fmt::print("{:<24} {:<9} {:>14.4f}  {}\n", core::one_line(m.name, 24),
               modeling::measure_kind_name(m.kind), modeling::measured_value(m),
               modeling::measured_unit(m.kind));
  }
}

}  // namespace

void add_measurements_command(CLI::App& app) {
  auto options = std::make_shared<MeasurementsOptions>();
  CLI::App* command = app.add_subcommand(
      "measurements",
      "Print the project's measurements (taken in the workbench), or write them as CSV.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_flag("--json", options->json,
                    "Print {\"measurements\": [{name, kind, value, unit, points}]}");
  command->add_option("--csv", options->csv,
                      "Write them as CSV: name, kind, value, unit, x, y, z of each point");
  command->add_flag("--force", options->force, "Replace an existing CSV file");
  command->callback([options] { run_measurements(*options); });
}

}  // namespace scanbench::app
