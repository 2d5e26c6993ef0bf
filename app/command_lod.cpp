// scanbench lod PROJECT [--rebuild] [--threads N] [--memory-limit SIZE] [--json]
#include <fmt/core.h>
#include <malloc.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.hpp"
#include "app/progress_bar.hpp"
#include "modeling/lod/update_lod.hpp"

namespace scanbench::app {
namespace {

struct LodOptions {
  std::string project;
  int threads = 0;
  std::uint64_t memory_limit = 0;
  bool json = false;
  bool rebuild = false;
};

nlohmann::json result_json(const lod::LodUpdateResult& r) {
  return {{"store", r.store.string()},
          {"updated", true},
          {"from_revision", r.from_revision},
          {"project_revision", r.project_revision},
          {"scans_read", r.scans_read},
          {"scans_added", r.scans_added},
          {"points_added", r.points_added},
          {"points_removed", r.points_removed},
          {"points_relabelled", r.points_relabelled},
          {"nodes_read", r.nodes_read},
          {"nodes_written", r.nodes_written},
          {"nodes_removed", r.nodes_removed},
          {"points", r.points},
          {"nodes", r.nodes},
          {"seconds", r.seconds},
          {"phase_seconds",
           {{"read", r.read_seconds}, {"edit", r.edit_seconds}, {"write", r.write_seconds}}}};
}

nlohmann::json result_json(const lod::LodBuildResult& r, const std::string& why_built) {
  return {{"store", r.store.string()},
          {"updated", false},
          {"why_built", why_built},
          {"project_revision", r.project_revision},
          {"scans", r.scans},
          {"in_model", r.in_model},
          {"merged_away", r.merged_away},
          {"deleted", r.deleted},
          {"points", r.points},
          {"nodes", r.nodes},
          {"chunks", r.chunks},
          {"threads", r.threads},
          {"store_bytes", r.store_bytes},
          {"seconds", r.seconds},
          {"phase_seconds",
           {{"survey", r.survey_seconds},
            {"distribute", r.distribute_seconds},
            {"chunks", r.chunk_seconds},
            {"top", r.top_seconds}}},
          {"points_per_second", r.seconds > 0.0 ? static_cast<double>(r.points) / r.seconds : 0.0}};
}

// The build allocates and frees arrays of megabytes band after band and
// chunk after chunk. By default glibc maps each one anew from the kernel and
// gives it back when freed, and on a virtual machine the page faults of
// those fresh pages cost a good part of the build (the campus on 2 cores:
// about 7.1 s without this, 5.8 s with it; three runs each). Arrays under
// 32 MB (the most glibc allows here) then come from the heap, which keeps up
// to 256 MB of freed memory for the next ones. A process-wide setting, so
// here and not in the library; best effort (mallopt returns 0 when it
// declines: the build is then slower).
void keep_freed_arrays_for_the_build() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

void run_lod(const LodOptions& options) {
  keep_freed_arrays_for_the_build();
  const store::Project project = store::Project::open_for_reading(options.project);
  lod::LodBuildSettings settings;
  settings.threads = options.threads;
  settings.memory_limit_bytes = memory_limit_of(options.memory_limit);
  ProgressBar progress;
  lod::LodRefreshResult refresh;
  if (options.rebuild) {
    refresh.built = naming_project(options.project,
                                   [&] { return lod::build_lod(project, settings, progress); });
    refresh.why_built = "asked to (--rebuild)";
  } else {
    refresh = naming_project(options.project,
                             [&] { return lod::refresh_lod(project, settings, progress); });
  }
  if (refresh.updated) {
    const lod::LodUpdateResult& r = *refresh.updated;
    if (options.json) {
      fmt::print("{}\n", result_json(r).dump());
      return;
    }
    fmt::print(
        "level-of-detail store updated in place ({:.2f} s): {} scan(s) compared, {} new; {} points "
        "added, {} removed, {} relabelled; {} nodes written, {} removed; {} points in {} nodes, "
        "{}\n",
        r.seconds, r.scans_read, r.scans_added, r.points_added, r.points_removed,
        r.points_relabelled, r.nodes_written, r.nodes_removed, r.points, r.nodes, r.store.string());
    return;
  }
  const lod::LodBuildResult& result = *refresh.built;
  if (options.json) {
    fmt::print("{}\n", result_json(result, refresh.why_built).dump());
    return;
  }
  fmt::print(
      "level-of-detail store of {} scan(s) built ({}): {} points in {} nodes ({} chunks, {} "
      "threads, {:.2f} s, {:.2f} M points/s), {:.1f} MB in {}\n",
      result.scans, refresh.why_built, result.points, result.nodes, result.chunks, result.threads,
      result.seconds,
      result.seconds > 0.0 ? 1e-6 * static_cast<double>(result.points) / result.seconds : 0.0,
      1e-6 * static_cast<double>(result.store_bytes), result.store.string());
}

}  // namespace

std::filesystem::path current_lod_store(const store::Project& project, double& built_seconds) {
  built_seconds = 0.0;
  if (const std::optional<std::filesystem::path> current = lod::current_lod_store(project))
    return *current;
  keep_freed_arrays_for_the_build();
  ProgressBar progress;
  const lod::LodRefreshResult result = naming_project(
      project.path(), [&] { return lod::refresh_lod(project, lod::LodBuildSettings{}, progress); });
  built_seconds = result.seconds();
  return result.store();
}

void add_lod_command(CLI::App& app) {
  auto options = std::make_shared<LodOptions>();
  CLI::App* command = app.add_subcommand(
      "lod",
      "Build or update the project's level-of-detail store (PROJECT.lod beside it): the shown "
      "model in a nested octree that the renderer streams from. A store that the project's "
      "commands since can be followed in place is updated, rewriting only the nodes that hold "
      "changed points; otherwise it is built anew. A cache: the project never needs it, and a "
      "failed or cancelled build or update leaves the old store as it was.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_flag("--rebuild", options->rebuild,
                    "Build the store anew even where it could be updated in place");
  add_threads_option(command, options->threads);
  add_memory_limit_option(command, options->memory_limit);
  command->add_flag("--json", options->json, "Print one JSON object");
  command->callback([options] { run_lod(*options); });
}

}  // namespace scanbench::app
