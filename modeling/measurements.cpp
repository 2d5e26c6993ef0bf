#include "modeling/measurements.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/errors.hpp"
#include "modeling/command_json.hpp"

namespace scanbench::modeling {

namespace {

constexpr std::string_view kNames[] = {"point", "distance", "height", "angle", "area"};
constexpr const char* kCommand = "measure";

nlohmann::json to_json(const Measurement& m) {
  nlohmann::json points = nlohmann::json::array();
  for (const Eigen::Vector3d& p : m.points) points.push_back({p.x(), p.y(), p.z()});
  return {{"name", m.name}, {"kind", measure_kind_name(m.kind)}, {"points", points}};
}

void check(const Measurement& m, std::size_t index) {
  const auto refuse = [&](const std::string& problem) {
    throw core::InputError("measurement " + std::to_string(index + 1), {}, problem);
  };
  if (m.name.empty()) refuse("has no name");
  const std::size_t n = m.points.size();
  const std::size_t needed = points_needed(m.kind);
  if (takes_more_points(m.kind) ? n < needed : n != needed) {
    refuse(std::string(measure_kind_name(m.kind)) + " takes " +
           (takes_more_points(m.kind) ? "at least " : "") + std::to_string(needed) +
           " points, not " + std::to_string(n));
  }
  for (const Eigen::Vector3d& p : m.points) {
    if (!p.allFinite()) refuse("a coordinate is not a finite number");
  }
}

}  // namespace

std::string_view measure_kind_name(MeasureKind kind) {
  return kNames[static_cast<int>(kind)];
}

std::optional<MeasureKind> measure_kind_from_name(std::string_view name) {
  for (int k = 0; k < 5; ++k) {
    if (kNames[k] == name) return static_cast<MeasureKind>(k);
  }
  return std::nullopt;
}

std::size_t points_needed(MeasureKind kind) {
  switch (kind) {
    case MeasureKind::kPoint:
      return 1;
    case MeasureKind::kDistance:
    case MeasureKind::kHeight:
      return 2;
    case MeasureKind::kAngle:
    case MeasureKind::kArea:
      return 3;
  }
  return 1;
}

bool takes_more_points(MeasureKind kind) {
  return kind == MeasureKind::kArea;
}

double measured_value(const Measurement& m) {
  const std::vector<Eigen::Vector3d>& p = m.points;
  assert(p.size() >= points_needed(m.kind) && "a measurement short of points");
  switch (m.kind) {
    case MeasureKind::kPoint:
      return p[0].z();
    case MeasureKind::kDistance:
      return (p[1] - p[0]).norm();
    case MeasureKind::kHeight:
      return p[1].z() - p[0].z();
    case MeasureKind::kAngle: {
      const Eigen::Vector3d a = p[0] - p[1], b = p[2] - p[1];
      return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
    }
    case MeasureKind::kArea: {
      // Newell's vector: twice the area vector of the closed polygon,
      // relative to its first point (for precision far from the origin).
      Eigen::Vector3d twice = Eigen::Vector3d::Zero();
      for (std::size_t k = 1; k + 1 < p.size(); ++k)
        twice += (p[k] - p[0]).cross(p[k + 1] - p[0]);
      return 0.5 * twice.norm();
    }
  }
  return 0.0;
}

std::string_view measured_unit(MeasureKind kind) {
  return kind == MeasureKind::kAngle ? "deg" : kind == MeasureKind::kArea ? "m2" : "m";
}

std::vector<Measurement> load_measurements(const store::Project& project) {
  const std::optional<std::string> stored = project.latest_result(kCommand);
  if (!stored) return {};
  std::vector<Measurement> out;
  try {
    const nlohmann::json j = nlohmann::json::parse(*stored);
    for (const nlohmann::json& e : j.at("measurements")) {
      Measurement m;
      m.name = e.at("name").get<std::string>();
      const std::optional<MeasureKind> kind =
          measure_kind_from_name(e.at("kind").get<std::string>());
      if (!kind) continue;  // a kind of a newer scanbench
      m.kind = *kind;
      for (const nlohmann::json& p : e.at("points"))
        m.points.emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
      check(m, out.size());
      out.push_back(std::move(m));
    }
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(project.path().string(), {{}, {}, "the newest measure command"},
                           std::string("unreadable measurements: ") + e.what());
  } catch (const core::InputError& e) {
    throw core::InputError(project.path().string(), {{}, {}, "the newest measure command"},
                           e.file() + " " + e.problem());
  }
  return out;
}

std::int64_t save_measurements(store::Project& project, const std::vector<Measurement>& list,
                               const std::string& what, std::int64_t based_on_revision) {
  const std::int64_t revision = based_on_revision;
  nlohmann::json all = nlohmann::json::array();
  for (std::size_t k = 0; k < list.size(); ++k) {
    check(list[k], k);
    all.push_back(to_json(list[k]));
  }
  store::Project::Edit edit = project.begin_command(kCommand, dump({{"what", what}}), revision);
  const std::int64_t id = edit.command_id();
  edit.commit(dump({{"measurements", all}}));
  return id;
}

std::string measurements_csv(const std::vector<Measurement>& list) {
  std::size_t most = 0;
  for (const Measurement& m : list) most = std::max(most, m.points.size());
  std::string out = "name,kind,value,unit";
  for (std::size_t k = 1; k <= most; ++k) out += fmt::format(",x{0},y{0},z{0}", k);
  out += '\n';
  for (const Measurement& m : list) {
    // Names are quoted, with their quotes doubled.
    std::string name;
    for (const char c : m.name) name += c == '"' ? std::string("\"\"") : std::string(1, c);
    // The shortest text that reads back as the same double.
    out += fmt::format("\"{}\",{},{},{}", name, measure_kind_name(m.kind), measured_value(m),
                       measured_unit(m.kind));
    for (const Eigen::Vector3d& p : m.points) out += fmt::format(",{},{},{}", p.x(), p.y(), p.z());
    out += '\n';
  }
  return out;
}

}  // namespace scanbench::modeling
