// `scanbench bench io`: raw-scan import and export throughput.
//
// One synthetic panoramic scan (a room seen from inside, with a band of
// missing returns) is written as PTX and as an ASCII organized PCD holding
// the same points. Our PTX reader is timed against PCL's PCD reader on the
// same data (the nearest peer: PCL has no PTX reader), plus our PTX writer
// and the project's store and load of the scan.
#pragma once

#include <nlohmann/json.hpp>

#include "bench/bench_suites.hpp"

namespace scanbench::bench {

// Fields: rows, columns, points, ptx_bytes, ptx_read_mb_per_s,
// ptx_read_points_per_s, ptx_write_mb_per_s, pcl_pcd_ascii_read_mb_per_s,
// ptx_read_speedup_vs_pcl (ratio of points per second), project_store_seconds,
// project_load_seconds, project_bytes_per_point. Times are the best of three.
nlohmann::json run_io_bench(const BenchOptions& options);

}  // namespace scanbench::bench
