#include "bench/bench_lod.hpp"

#include <stdexcept>
#include <string>

#include "acquisition/simulation/virtual_scanner.hpp"
#include "bench/child_process.hpp"
#include "bench/scratch_folder.hpp"
#include "bench/simulated_site.hpp"

namespace scanbench::bench {
namespace {

// `scanbench lod` on `project` with `threads` (0: every core), its JSON
// with the process's wall time and peak memory.
nlohmann::json timed_build(const std::filesystem::path& project, int threads,
                           const std::filesystem::path& dir) {
  const std::string stage = "lod_" + std::to_string(threads);
  const ChildRun run = run_scanbench(
      stage, {"lod", project.string(), "--json", "--threads", std::to_string(threads)}, dir);
  if (run.exit_code != 0) {
    throw std::runtime_error("bench lod: scanbench lod exited with " +
                             std::to_string(run.exit_code) + ": " + run.err);
  }
  nlohmann::json built = nlohmann::json::parse(run.out);
  built["process_seconds"] = run.seconds;
  built["peak_rss_bytes"] = run.peak_rss_bytes;
  return built;
}

}  // namespace

nlohmann::json run_lod_bench(const BenchOptions& options) {
  acquisition::sim::ScannerModel scanner;
  if (options.smoke) {
    scanner.columns = 900;
    scanner.rows = 225;
  }
  const SimulatedSite site =
      simulate_site("campus", scanner, options.smoke ? 2 : 4, SiteLighting::kReference);
  const ScratchFolder scratch("lod");
  const std::filesystem::path project = scratch.path() / "campus.sbproj";
  store_site_project(site, project);

  const nlohmann::json all = timed_build(project, 0, scratch.path());
  const nlohmann::json one = timed_build(project, 1, scratch.path());
  const double points = all["points"].get<double>();
  const int threads = all["threads"].get<int>();
  const double seconds = all["seconds"].get<double>();
  nlohmann::json out;
  out["suite"] = "lod";
  out["points"] = all["points"];
  out["nodes"] = all["nodes"];
  out["store_bytes"] = all["store_bytes"];
  out["phase_seconds"] = all["phase_seconds"];
  out["threads"] = threads;
  out["build_points_per_second"] = points / seconds;
  out["build_points_per_second_per_thread"] = points / seconds / threads;
  out["build_peak_rss_bytes"] = all["peak_rss_bytes"];
  out["full_rebuild_seconds"] = seconds;
  out["one_thread"] = {{"build_points_per_second", points / one["seconds"].get<double>()},
                       {"build_peak_rss_bytes", one["peak_rss_bytes"]},
                       {"seconds", one["seconds"]},
                       {"phase_seconds", one["phase_seconds"]}};
  // Not built yet: the streaming renderer, edits in place, 3D selection.
  for (const char* field :
       {"first_frame_ms", "frame_ms_p50", "frame_ms_p95", "points_per_frame_p50",
        "render_peak_rss_bytes", "gpu_cache_bytes_peak", "hide_ms", "recolor_ms",
        "commit_1m_points_ms", "insert_scan_seconds"}) {
    out[field] = nullptr;
  }
  out["views"] = nlohmann::json::object();
  out["selection"] = nlohmann::json::array();
  return out;
}

}  // namespace scanbench::bench
