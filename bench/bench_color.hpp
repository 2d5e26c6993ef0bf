// `scanbench bench color`: colour harmonisation of the campus scans
// (issue 15) against the simulator's truth.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_color_bench(const BenchOptions& options);

}  // namespace scanbench::bench
