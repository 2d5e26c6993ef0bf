// `scanbench bench segmentation` (issue #13): seeded region growing on a
// simulated campus scan, against the truth's objects and PCL's region growing.
//
// JSON: suite, site, scan (1: the campaign's first), columns, rows, protocol;
//   ours: objects [{name, kind, channel, iou, operations, operations_to_0_95,
//     pixels}], mean_iou,
//     objects_at_least_0_95, click_latency_ms_p50, click_latency_ms_p95 (regions
//     up to 1 M pixels), clicks, clicks_over_1m_pixels,
//     click_latency_ms_p95_over_1m_pixels, click_latency_ms_p95_all,
//     largest_region_pixels, prepare_seconds;
//   ours_held_out: scan (2), objects, mean_iou, objects_at_least_0_95: the same
//     recipes on a scan they were not chosen on;
//   ours_auto (automatic proposals for the whole scan), pcl_region_growing,
//     pcl_region_growing_rgb: seconds, mean_iou, segments, objects [{name, iou}],
//     settings;
//   goals: every_object_iou_at_least_0_95_within_3_operations,
//     click_latency_p95_at_most_16_ms.
// With --smoke: a 900 × 225 scan; figures not meaningful.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_segmentation_bench(const BenchOptions& options);

}  // namespace scanbench::bench
