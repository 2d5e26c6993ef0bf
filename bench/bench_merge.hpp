// `scanbench bench merge` (issues #5, #11): merge keep masks, at the true
// poses and at registered ones, judged against the simulator's truth: how
// much of the redundancy they remove and how much surface stays covered.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

// Fields (definitions at the top of bench_merge.cpp): suite, site, scans,
// columns, rows, threads;
//   ours (merged at the true poses) and ours_registered (at the poses our
//     registration finds from perturbed ones): redundant_removed_share,
//     redundant_removed_share_by_spacing, unique_removed_share,
//     coverage_before, coverage_after, coverage_drop, coverage_samples,
//     points_per_second, points, kept_points, truth_redundant_points,
//     truth_redundant_points_by_spacing, truth_unique_points, seconds,
//     prepare_seconds; ours_registered adds registration
//     {max_rotation_error_deg, max_translation_error_m, converged, seconds,
//     max_initial_error};
//   goals (for ours) and goals_registered: redundant_removed_share_at_least_0_9,
//     redundant_removed_share_by_spacing_at_least_0_9,
//     coverage_drop_at_most_0_005, points_per_second_at_least_20m.
// With --smoke: 2 scans of 900 × 225, one merge run each.
nlohmann::json run_merge_bench(const BenchOptions& options);

}  // namespace scanbench::bench
