// `scanbench bench geometry`: per-point normals and mixed-pixel flags
// (acquisition/scan_geometry) against the simulator's exact truth, side by
// side with PCL's integral-image and kNN normal estimators on the same
// organized clouds (issue #4).
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

// Simulates scans of the "campus" site (seed 1; the first two poses of a
// 4-scan campaign at 3600 × 900, or one at 360 × 90 with --smoke) and returns:
//   top level: suite, site, columns, rows, scans, points (valid points over
//     all scans);
//   speedup_vs_PEER for every PCL peer: ours' points per second (all cores)
//     ÷ the peer's (on its own thread count, see its "threads");
//   speedup_vs_PEER_1_thread for the single-threaded peers (the integral
//     images): ours_1_thread's points per second ÷ the peer's, thread for
//     thread; speedup_goal_1_thread (5) and goals: median_below_every_pcl,
//     speedup_1_thread_at_least_5x_vs_average_3d_gradient (judged on
//     speedup_vs_pcl_integral_average_3d_gradient_1_thread),
//     mixed_recall_at_least_0_9_false_rate_at_most_0_01;
//   one object per method — ours (all cores), ours_1_thread, and the peers
//     pcl_integral_covariance, pcl_integral_average_3d_gradient (smoothing
//     30, one thread), pcl_knn_omp (k = 50, two threads),
//     pcl_integral_covariance_smoothing_33 and
//     pcl_integral_average_3d_gradient_smoothing_33 (PCL's window as wide as
//     our widest, 33 pixels; not equal support: see bench_geometry.cpp) —
//     with median_error_deg, p95_error_deg, planar_median_error_deg,
//     coverage, points_per_second, seconds, threads, settings; ours and
//     ours_1_thread add mixed_pixel_recall, mixed_pixel_false_rate and
//     truth_mixed_pixels.
// Errors are sign-agnostic angles to the truth normal over valid pixels that
// have a truth normal, are not truth mixed pixels and got a normal; null when
// no pixel qualifies. Times are the best of five runs (kNN: two; one with
// --smoke).
nlohmann::json run_geometry_bench(const BenchOptions& options);

}  // namespace scanbench::bench
