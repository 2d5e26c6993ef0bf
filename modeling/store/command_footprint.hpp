// What each command of the journal reads and writes, by kind of data. Two
// processes may work on one project at once (a harmonize in a terminal, the
// workbench beside it); a command whose computation began before another
// process's change conflicts with it only when that change wrote data the
// command read, so a recolour never voids a harmonize while a re-registration
// still voids a merge computed on the old poses.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace scanbench::store {

// The kinds of data a command touches; a set of them is a bit mask.
enum class ProjectData : std::uint32_t {
  kScans = 1u << 0,             // the scans' records, channels, sources and images
  kGeometry = 1u << 1,          // footprints, normals, confidence
  kPoses = 1u << 2,             // the scans' poses in the world
  kMerge = 1u << 3,             // which points the merged model keeps
  kColorCorrections = 1u << 4,  // harmonize's per-scan colour corrections
  kObjects = 1u << 5,           // the object tree, memberships, object colours
  kMeasurements = 1u << 6,      // the measurements list
  kSelections = 1u << 7,        // selections kept for the next session (no command reads them)
  // Which object owns each point (the membership layers): a part of the
  // objects that a hide, a rename or a recolour leaves as it was.
  kMembership = 1u << 8,
};

using ProjectDataSet = std::uint32_t;
inline constexpr ProjectDataSet kAllProjectData = (1u << 9) - 1;

constexpr ProjectDataSet operator|(ProjectData a, ProjectData b) {
  return static_cast<ProjectDataSet>(a) | static_cast<ProjectDataSet>(b);
}
constexpr ProjectDataSet operator|(ProjectDataSet a, ProjectData b) {
  return a | static_cast<ProjectDataSet>(b);
}

struct CommandFootprint {
  ProjectDataSet reads = kAllProjectData;
  ProjectDataSet writes = kAllProjectData;
};

// The footprint of the command journaled as `name`; a name it does not know
// (a newer scanbench's command) reads and writes everything.
CommandFootprint footprint_of(std::string_view name);

// The name of one kind of data in messages ("colour corrections"), and its
// key in the project's meta table ("color_corrections").
const char* data_name(ProjectData data);
const char* data_key(ProjectData data);

// The kinds in `set`, in the enumeration's order.
std::vector<ProjectData> data_in(ProjectDataSet set);

}  // namespace scanbench::store
