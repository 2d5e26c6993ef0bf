#include "modeling/store/command_footprint.hpp"

#include <array>
#include <utility>
#include <vector>

namespace scanbench::store {
namespace {

using D = ProjectData;

// Everything a command on the object tree computes from: the points and
// where they are (an object's figures and its growth into other scans).
constexpr ProjectDataSet kObjectInputs = D::kScans | D::kGeometry | D::kPoses | D::kObjects;

constexpr std::array<std::pair<std::string_view, CommandFootprint>, 18> kFootprints = {{
    {"import", {0, D::kScans | D::kPoses | D::kMerge}},
    {"geometry", {static_cast<ProjectDataSet>(D::kScans), D::kGeometry | D::kMerge}},
    {"register",
     {kObjectInputs, D::kPoses | D::kMerge | D::kObjects}},
    {"merge", {D::kScans | D::kGeometry | D::kPoses, static_cast<ProjectDataSet>(D::kMerge)}},
    {"harmonize",
     {D::kScans | D::kGeometry | D::kPoses | D::kColorCorrections,
      static_cast<ProjectDataSet>(D::kColorCorrections)}},
    {"select", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},  // older journals
    {"keep_selection", {0, static_cast<ProjectDataSet>(D::kObjects)}},
    {"commit", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"separate", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"propose", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"delete", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"group", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"edit", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"ungroup", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"merge_objects", {kObjectInputs, static_cast<ProjectDataSet>(D::kObjects)}},
    {"recolor", {static_cast<ProjectDataSet>(D::kObjects), static_cast<ProjectDataSet>(D::kObjects)}},
    // A clone measures the source's colours as shown: corrections included.
    {"clone", {kObjectInputs | D::kColorCorrections, static_cast<ProjectDataSet>(D::kObjects)}},
    {"measure",
     {static_cast<ProjectDataSet>(D::kMeasurements), static_cast<ProjectDataSet>(D::kMeasurements)}},
}};

}  // namespace

CommandFootprint footprint_of(std::string_view name) {
  for (const auto& [known, footprint] : kFootprints) {
    if (known == name) return footprint;
  }
  return {};
}

namespace {

struct DataNames {
  ProjectData data;
  const char* key;   // in table meta: "changed.<key>"
  const char* name;  // in messages
};

constexpr std::array<DataNames, 7> kDataNames = {{
    {D::kScans, "scans", "scans"},
    {D::kGeometry, "geometry", "geometry"},
    {D::kPoses, "poses", "poses"},
    {D::kMerge, "merge", "merged model"},
    {D::kColorCorrections, "color_corrections", "colour corrections"},
    {D::kObjects, "objects", "objects"},
    {D::kMeasurements, "measurements", "measurements"},
}};

const DataNames& names_of(ProjectData data) {
  for (const DataNames& names : kDataNames) {
    if (names.data == data) return names;
  }
  return kDataNames[0];  // unreachable: every enumerator is listed
}

}  // namespace

const char* data_name(ProjectData data) {
  return names_of(data).name;
}

const char* data_key(ProjectData data) {
  return names_of(data).key;
}

std::vector<ProjectData> data_in(ProjectDataSet set) {
  std::vector<ProjectData> out;
  for (const DataNames& names : kDataNames) {
    if ((set & static_cast<ProjectDataSet>(names.data)) != 0) out.push_back(names.data);
  }
  return out;
}

}  // namespace scanbench::store
