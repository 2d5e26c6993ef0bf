// Measurements taken on the model (the workbench's picks): a point's
// coordinates, a distance, a height difference, an angle and a polygon's
// area, in the project's world coordinates (georeferenced values as they
// are). The project keeps the list: each change is one journaled command
// ("measure") whose result holds the whole list, so undo and redo bring
// earlier lists back and the newest done one is what the project holds.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "modeling/store/project.hpp"

namespace scanbench::modeling {

enum class MeasureKind { kPoint, kDistance, kHeight, kAngle, kArea };

// "point", "distance", "height", "angle", "area"; and back (none: unknown).
std::string_view measure_kind_name(MeasureKind kind);
std::optional<MeasureKind> measure_kind_from_name(std::string_view name);

// How many points a kind takes: exactly (point 1, distance and height 2,
// angle 3: the vertex in the middle), or at least (area 3).
std::size_t points_needed(MeasureKind kind);
bool takes_more_points(MeasureKind kind);  // area: any number from 3

struct Measurement {
  std::string name;
  MeasureKind kind = MeasureKind::kPoint;
  std::vector<Eigen::Vector3d> points;  // world [m]
};

// The measured value: a point's height (z) [m], the distance [m], the
// height difference second − first [m], the angle at the middle point
// [deg], or the area of the polygon through the points [m²] (planar or
// not: the area of its best plane's projection, Newell's vector). Asserts
// the kind's number of points.
double measured_value(const Measurement& m);
// The value's unit: "m", "deg" or "m2".
std::string_view measured_unit(MeasureKind kind);

// The project's measurements (none before the first). Throws
// core::InputError naming the project and the command when the stored list
// is malformed.
std::vector<Measurement> load_measurements(const store::Project& project);

// Makes `list` the project's measurements in one command, `what` saying
// why ("add distance 1"). `based_on_revision` is the project's revision
// when the list it was made from was read: another process's change since
// refuses it (the project's concurrency rule), so no measurement is lost.
// Refuses (core::InputError, nothing written) a measurement with the wrong
// number of points, a non-finite coordinate or an empty name. Returns the
// command's id.
std::int64_t save_measurements(store::Project& project, const std::vector<Measurement>& list,
                               const std::string& what, std::int64_t based_on_revision);

// The list as CSV: name (quoted), kind, value, unit, then x, y, z of each
// point; a header line first (x1, y1, z1, … for the most points any
// measurement has); each number the shortest text that reads back as the
// same double, '.' decimals.
std::string measurements_csv(const std::vector<Measurement>& list);

}  // namespace scanbench::modeling
