// Benchmark suites behind `scanbench bench SUITE`. Each suite measures
// accuracy and/or speed, peers (PCL) side by side in the same run, and
// returns one JSON object with the field names its issue specifies.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace scanbench::bench {

struct BenchOptions {
  // Small inputs for the test suite's smoke run: same code paths, seconds
  // instead of minutes, figures not meaningful.
  bool smoke = false;
  // Where a suite that draws pictures (render) writes them; empty: nowhere.
  std::filesystem::path pictures;
  // scale: campaign sizes [stations], the scans' resolution and the site.
  std::vector<int> sizes{1, 4, 16, 64};
  int columns = 3600;
  int rows = 900;
  std::string site = "campus";
};

std::vector<std::string> suite_names();

// Runs one suite. Asserts `name` is one of suite_names() (the CLI checks it).
nlohmann::json run_suite(const std::string& name, const BenchOptions& options);

}  // namespace scanbench::bench
