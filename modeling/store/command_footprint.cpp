#include "modeling/store/command_footprint.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <utility>
#include <vector>

namespace scanbench::store {
namespace {

using D = ProjectData;

// Everything a command on the object tree computes from: the points and
// where they are (an object's figures and its growth into other scans).
constexpr ProjectDataSet kObjectInputs =
    D::kScans | D::kGeometry | D::kPoses | D::kObjects | D::kMembership;
// What a command that moves points between objects writes.
constexpr ProjectDataSet kObjectsAndPoints = D::kObjects | D::kMembership;

constexpr ProjectDataSet only(ProjectData data) {
  return static_cast<ProjectDataSet>(data);
}

constexpr std::array<std::pair<std::string_view, CommandFootprint>, 18> kFootprints = {{
    {"import", {0, D::kScans | D::kPoses | D::kMerge}},
    {"geometry", {only(D::kScans), D::kGeometry | D::kMerge}},
    {"register", {kObjectInputs, D::kPoses | D::kMerge | kObjectsAndPoints}},
    {"merge", {D::kScans | D::kGeometry | D::kPoses, only(D::kMerge)}},
    {"harmonize",
     {D::kScans | D::kGeometry | D::kPoses | D::kColorCorrections, only(D::kColorCorrections)}},
    {"select", {kObjectInputs, only(D::kSelections)}},  // in older journals
    {"keep_selection", {0, only(D::kSelections)}},
    {"commit", {kObjectInputs, kObjectsAndPoints | D::kSelections}},  // it removes a kept selection
    {"separate", {kObjectInputs, kObjectsAndPoints}},
    {"propose", {kObjectInputs, kObjectsAndPoints}},
    {"delete", {kObjectInputs, kObjectsAndPoints}},
    {"group", {kObjectInputs, only(D::kObjects)}},
    {"edit", {kObjectInputs, only(D::kObjects)}},
    {"ungroup", {kObjectInputs, only(D::kObjects)}},
    {"merge_objects", {kObjectInputs, kObjectsAndPoints}},
    {"recolor", {only(D::kObjects), only(D::kObjects)}},
    // A clone measures the source's colours as shown: corrections included.
    {"clone", {kObjectInputs | D::kColorCorrections, only(D::kObjects)}},
    {"measure", {only(D::kMeasurements), only(D::kMeasurements)}},
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

constexpr std::array<DataNames, 9> kDataNames = {{
    {D::kScans, "scans", "scans"},
    {D::kGeometry, "geometry", "geometry"},
    {D::kPoses, "poses", "poses"},
    {D::kMerge, "merge", "merged model"},
    {D::kColorCorrections, "color_corrections", "colour corrections"},
    {D::kObjects, "objects", "objects"},
    {D::kMeasurements, "measurements", "measurements"},
    {D::kSelections, "selections", "kept selections"},
    {D::kMembership, "membership", "objects' points"},
}};

const DataNames& names_of(ProjectData data) {
  const auto found = std::find_if(kDataNames.begin(), kDataNames.end(),
                                  [&](const DataNames& names) { return names.data == data; });
  assert(found != kDataNames.end() && "a kind of data missing from kDataNames");
  return *found;
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
