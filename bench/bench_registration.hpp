// `scanbench bench registration` (issues #5, #11): our registration pipeline
// against the simulator's true poses, with and without global refinement,
// and PCL's point-to-plane ICP on our gate schedule from the same starts in
// the same run.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

// Fields: suite, sites, scans_per_site, columns, rows, threads (all cores),
// max_initial_error {rotation_deg, translation_m};
//   ours, ours_one_thread, ours_pairwise, ours_pairwise_one_thread,
//   pcl_icp_point_to_plane: max_rotation_error_deg, max_translation_error_m,
//     median_rotation_error_deg, median_translation_error_m, seconds (fine
//     stage per campaign), converged_pair_share; ours… add icp_seconds (the
//     chosen ICP run of every pair, per campaign); ours adds
//     coarse_success_rate, coarse_accepted_but_wrong, coarse_seconds,
//     trials; PCL adds settings;
//   speed ratios, PCL's seconds ÷ ours: fine_speedup_vs_pcl[_one_thread]
//     (the full pipeline's fine stage, global refinement included),
//     pairwise_speedup_vs_pcl[_one_thread] (pairwise fine stage),
//     pairwise_icp_speedup_vs_pcl[_one_thread] (chosen runs only);
//   speedup_goal (5) and goals: accuracy_within_0_02_deg_and_3_mm (ours),
//     pairwise_speedup_one_thread_at_least_5x.
// With --smoke: one site, 2 scans of 900 × 225, one trial.
nlohmann::json run_registration_bench(const BenchOptions& options);

}  // namespace scanbench::bench
