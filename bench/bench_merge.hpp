// `scanbench bench merge` (issue #5): merge keep masks judged against the
// simulator's truth: how much of the redundancy they remove and how much
// surface stays covered.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_merge_bench(const BenchOptions& options);

}  // namespace scanbench::bench
