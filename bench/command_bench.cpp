// scanbench bench SUITE [--json] [--smoke] [--pictures DIR] [--sizes N,N,...] [--columns C]
//                       [--rows R] [--site S]
#include <fmt/core.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.hpp"
#include "bench/bench_suites.hpp"

namespace scanbench::app {
namespace {

struct BenchCommandOptions {
  std::string suite;
  bool json = false;
  bench::BenchOptions bench;
};

// One line per figure; nested objects as "method.field" paths.
void print_table(const nlohmann::json& value, const std::string& path) {
  if (value.is_object()) {
    for (const auto& [key, child] : value.items()) {
      print_table(child, path.empty() ? key : path + "." + key);
    }
    return;
  }
  fmt::print("{:<50} {}\n", path, value.dump());
}

void run_bench(const BenchCommandOptions& options) {
  const nlohmann::json result = bench::run_suite(options.suite, options.bench);
  if (options.json) {
    fmt::print("{}\n", result.dump());
    return;
  }
  print_table(result, "");
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto options = std::make_shared<BenchCommandOptions>();
  CLI::App* command = app.add_subcommand("bench", kBenchDescription);
  command->add_option("suite", options->suite, "Suite to run")
      ->required()
      ->check(CLI::IsMember(bench::suite_names()));
  command->add_flag("--json", options->json, "Print one JSON object");
  command->add_flag("--smoke", options->bench.smoke,
                    "Tiny inputs: checks the suite runs; figures are not meaningful");
  command->add_option("--pictures", options->bench.pictures,
                      "render: also write each view's truth picture and renders (PNG) here; "
                      "lod: each 3D selection's views, the object's points taken and missed");
  command
      ->add_option("--sizes", options->bench.sizes,
                   "scale: campaign sizes in stations, comma-separated (default 1,4,16,64)")
      ->delimiter(',')
      ->check(CLI::Range(1, 64));
  command->add_option("--columns", options->bench.columns, "scale: columns of each scan (3600)")
      ->check(CLI::Range(8, 36000));
  command->add_option("--rows", options->bench.rows, "scale: rows of each scan (900)")
      ->check(CLI::Range(4, 18000));
  command->add_option("--site", options->bench.site, "scale: simulated site (campus)");
  command->callback([options] { run_bench(*options); });
}

}  // namespace scanbench::app
