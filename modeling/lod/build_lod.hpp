// `scanbench lod`: builds a project's level-of-detail store (docs/lod.md)
// by streaming its scans, in bounded memory, as PotreeConverter 2 builds its
// octree (Schütz et al. 2020):
//   1. survey: every scan read a band at a time, counting its shown points
//      in the cells of a coarse grid over the model's cube (and its
//      intensity spread);
//   2. chunks: from those counts, the nodes whose regions hold few enough
//      points to be built in memory, and the few nodes above them;
//   3. distribute: every scan read again, each point parked in a temporary
//      file under its chunk;
//   4. chunks built in parallel (octree_sampling.hpp), their nodes stored;
//   5. the nodes above the chunks drawn from the chunks' roots.
// The result is the tree the whole model in memory would give, node for
// node: it does not depend on the threads or the memory limit.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "core/progress.hpp"
#include "modeling/lod/octree_sampling.hpp"
#include "modeling/lod/shown_points.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::lod {

struct LodBuildSettings {
  OctreeSettings octree;
  ShownPointsSettings points;
  int threads = 0;  // 0: every core
  // What the build may hold in memory [bytes]; none: from the machine
  // (modeling::memory_limit_or_default).
  std::optional<std::uint64_t> memory_limit_bytes;
  // The most points a chunk holds; 0: from the memory limit and threads.
  std::size_t chunk_points = 0;
  // Where the store goes; empty: LodStore::path_for(the project).
  std::filesystem::path output;
};

struct LodBuildResult {
  std::filesystem::path store;
  std::int64_t project_revision = 0;
  std::size_t scans = 0;
  std::uint64_t in_model = 0;     // in-model points of every scan
  std::uint64_t merged_away = 0;  // dropped by the merge's keep masks
  std::uint64_t deleted = 0;      // marked deleted
  std::uint64_t points = 0;       // in the store
  std::uint64_t nodes = 0;
  std::size_t chunks = 0;  // built in memory one at a time
  int threads = 1;
  std::uint64_t store_bytes = 0;
  double seconds = 0.0;
  // Of which the phases (numbered as above): survey, distribute, chunks
  // (4) and top (5, with writing the file out).
  double survey_seconds = 0.0, distribute_seconds = 0.0, chunk_seconds = 0.0, top_seconds = 0.0;
};

// Builds the store of `project`'s current state, replacing the one there
// (a crash or a cancel leaves it as it was). Throws core::InputError when
// the project has no scan, a scan has no geometry or is damaged;
// core::MemoryShortage, before writing, when one chunk of the model cannot
// fit the memory limit; core::Cancelled through `progress`.
LodBuildResult build_lod(const store::Project& project, const LodBuildSettings& settings,
                         core::Progress& progress);

// What a store reflects of its project: a command that writes none of
// these (a harmonisation, a hide, a recolour, a measurement) leaves it
// current.
inline constexpr store::ProjectDataSet kLodInputs =
    store::ProjectData::kScans | store::ProjectData::kGeometry | store::ProjectData::kPoses |
    store::ProjectData::kMerge | store::ProjectData::kMembership;

// The store beside `project` (LodStore::path_for) when it reflects the
// project as it is now; none when it is missing, unreadable, or older than
// a change to its inputs.
std::optional<std::filesystem::path> current_lod_store(const store::Project& project);

}  // namespace scanbench::lod
