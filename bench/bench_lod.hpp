// `scanbench bench lod` (issue 29): the level-of-detail store. The campus
// (seed 1, 4 stations at 3600 × 900; smoke: 2 at 900 × 225) at its true
// poses with its geometry and merge, as the render bench has it; then
// `scanbench lod` in a process of its own, on every core and on one:
// "build_points_per_second" (the store's points over the whole build,
// reading the project included), "build_points_per_second_per_thread",
// "threads", "build_peak_rss_bytes" (the kernel's high-water mark of that
// process), "full_rebuild_seconds", and "one_thread" (the same on one
// core). "points", "nodes", "store_bytes" and "phase_seconds" describe the
// build. The figures of the streaming renderer and of edits in place are
// null until they exist.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_lod_bench(const BenchOptions& options);

}  // namespace scanbench::bench
