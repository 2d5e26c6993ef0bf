// `scanbench bench lod` (issue 29): the level-of-detail store and the
// streaming renderer. The campus (seed 1, 4 stations at 3600 × 900; smoke:
// 2 at 900 × 225) at its true poses with its geometry and merge, as the
// render bench has it. Then:
//   - `scanbench lod` in a process of its own, on every core and on one:
//     "build_points_per_second" (the store's points over the whole build,
//     reading the project included), "build_points_per_second_per_thread",
//     "threads", "build_peak_rss_bytes" (the kernel's high-water mark of
//     that process), "full_rebuild_seconds", and "one_thread" (the same on
//     one core); "points", "nodes", "store_bytes" and "phase_seconds"
//     describe the build;
//   - `scanbench render --path` in a process of its own: a fly-through of
//     300 frames at 960 × 540 (smoke: 30 at 240 × 135) along the street
//     and up to the overview, with a 100 ms frame-time target:
//     "first_frame_ms" (from the start of the command to the first frame
//     with points), "frame_ms_p50", "frame_ms_p95", "points_per_frame_p50",
//     "gpu_cache_bytes_peak", "render_peak_rss_bytes", and "path" (its
//     frame count, the slowest frame, the seconds to complete the last
//     picture once still);
//   - "views": for each bench camera, the streaming renderer from cold
//     caches, frame after frame (each waiting up to 250 ms for the nodes
//     being read, as the workbench refines) until the picture is complete
//     ("converge_seconds", "converge_frames"), that picture's PSNR against
//     the truth over the pixels some scan sampled ("converged_psnr_db"),
//     the full picture's (every point of the store drawn, no level of
//     detail: "full_renderer_psnr_db"), and the two pictures against each
//     other ("against_full_renderer_psnr_db").
//   - "selection": five objects of the truth (a façade, a tree, a car, a
//     lamp post, a low wall; of each kind the one the store holds most
//     points of) selected by lassos traced around their outlines in the
//     3D view (measure_selection in bench_lod.cpp says how the views are
//     chosen): "selection_iou" against the truth's points in the store,
//     what else the lassos took and what they missed by kind, and
//     "select_ms" for the chosen lassos; with --pictures, each view with
//     the object's points taken (yellow) and missed (red);
//   - "edits": a commit, hide, recolour, delete and undo, the store updated
//     in place ("hide_ms", "recolor_ms", "commit_1m_points_ms"), then a
//     new scan inserted ("insert_scan_seconds") against building the grown
//     campaign's store anew ("full_rebuild_seconds").
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

nlohmann::json run_lod_bench(const BenchOptions& options);

}  // namespace scanbench::bench
