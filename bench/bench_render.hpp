// `scanbench bench render`: the splat renderer against the simulator's truth
// pictures of the campus (issue 14), and what culling saves.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_render_bench(const BenchOptions& options);

}  // namespace scanbench::bench
