// `scanbench bench scale` (issue 28): how every batch stage grows with the
// campaign. For each size N (BenchOptions::sizes, default 1, 4, 16, 64) a
// campaign of N stations at columns × rows is simulated (site
// BenchOptions::site, every scan but the first written with a pose error of
// up to 3° and 0.5 m), and the stages run one after the other on one
// project, each in a process of its own (the `scanbench` beside the bench's
// executable where there is one): import, geometry, register, merge,
// harmonize (null for one station: no colour pairs), export_las (--merged).
// Per stage: "seconds" (wall, from spawn
// to exit), "points_per_second" (the campaign's valid points / seconds) and
// "peak_rss_bytes" (the kernel's maximum resident set of that process). A
// stage that fails or runs past 30 minutes reports "exit_code",
// "timed_out" and "error" instead, and the campaign goes on.
//
// Per campaign also: "scans", "points", "pair_tests" (pairs of scans the
// registration tested), the registration's "max_rotation_error_deg" and
// "max_translation_error_m" against the simulator's true poses, and
// "project_bytes". At the top: "columns", "rows", "site", and, where the
// sizes include 4 and a larger one, "rss_ratio" and "throughput_ratio" per
// stage: the largest size's peak RSS over that at 4 stations (goal ≤ 1.25),
// and its points per second over that at 4 (goal ≥ 0.8).
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_scale_bench(const BenchOptions& options);

}  // namespace scanbench::bench
