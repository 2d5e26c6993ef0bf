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
//     all scans), speedup_vs_pcl_integral_covariance,
//     speedup_vs_pcl_integral_average_3d_gradient, speedup_vs_pcl_knn_omp
//     (ours' points per second ÷ theirs), goals (the three targets);
//   one object per method — ours, pcl_integral_covariance,
//     pcl_integral_average_3d_gradient, pcl_knn_omp — with median_error_deg,
//     p95_error_deg, planar_median_error_deg, coverage, points_per_second,
//     seconds, threads, settings; ours adds mixed_pixel_recall and
//     mixed_pixel_false_rate; pcl_integral_covariance_window_7 and
//     pcl_integral_average_3d_gradient_window_7 (same fields, plus a
//     speedup_vs_ each) run PCL on our window size for an equal-support view.
// Errors are sign-agnostic angles to the truth normal over valid pixels that
// have a truth normal, are not truth mixed pixels and got a normal; null when
// no pixel qualifies. Times are the best of two runs (one with --smoke).
nlohmann::json run_geometry_bench(const BenchOptions& options);

}  // namespace scanbench::bench
