// `scanbench bench registration` (issue #5): our registration pipeline against
// the simulator's true poses, with PCL's point-to-plane ICP from the same
// post-coarse poses in the same run.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_registration_bench(const BenchOptions& options);

}  // namespace scanbench::bench
