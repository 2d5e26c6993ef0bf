#include "app/formats/point_pairs_file.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "acquisition/formats/json_input.hpp"
#include "core/errors.hpp"

namespace scanbench::app {
namespace {

constexpr std::uintmax_t kMaxPairsFileBytes = 16u << 20;

using nlohmann::json;

[[noreturn]] void bad(const std::filesystem::path& file, const std::string& where,
                      const std::string& problem) {
  throw core::InputError(file.string(), {std::nullopt, std::nullopt, where}, problem);
}

Eigen::Vector3d read_point(const json& value, const std::filesystem::path& file,
                           const std::string& where) {
  if (!value.is_array() || value.size() != 3) bad(file, where, "expected [x, y, z] in metres");
  Eigen::Vector3d point;
  for (int axis = 0; axis < 3; ++axis) {
    const json& v = value[static_cast<std::size_t>(axis)];
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      bad(file, where, "coordinates must be finite numbers");
    }
    point[axis] = v.get<double>();
  }
  return point;
}

std::int64_t read_id(const json& entry, const char* key, const std::filesystem::path& file,
                     const std::string& where) {
  if (!entry.contains(key) || !entry[key].is_number_integer()) {
    bad(file, where + "." + key, "expected a scan id (an integer; see scanbench info)");
  }
  return entry[key].get<std::int64_t>();
}

modeling::ProjectPicks read_entry(const json& entry, const std::filesystem::path& file,
                                  const std::string& where) {
  if (!entry.is_object()) bad(file, where, "expected an object");
  modeling::ProjectPicks picks;
  picks.source_id = read_id(entry, "source", file, where);
  picks.target_id = read_id(entry, "target", file, where);
  if (!entry.contains("points") || !entry["points"].is_array()) {
    bad(file, where + ".points", "expected an array of point pairs");
  }
  const json& points = entry["points"];
  if (points.size() < 3) bad(file, where + ".points", "at least 3 point pairs are needed");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string at = where + ".points[" + std::to_string(i) + "]";
    if (!points[i].is_object() || !points[i].contains("source_m") ||
        !points[i].contains("target_m")) {
      bad(file, at, "expected {\"source_m\": [x, y, z], \"target_m\": [x, y, z]}");
    }
    picks.pairs.push_back({read_point(points[i]["source_m"], file, at + ".source_m"),
                           read_point(points[i]["target_m"], file, at + ".target_m")});
  }
  return picks;
}

}  // namespace

std::vector<modeling::ProjectPicks> read_point_pairs_file(const std::filesystem::path& file) {
  const json document = acquisition::read_json_file(file, kMaxPairsFileBytes);
  if (!document.is_object() || !document.contains("pairs") || !document["pairs"].is_array()) {
    bad(file, "pairs", "expected {\"pairs\": [...]}");
  }
  std::vector<modeling::ProjectPicks> picks;
  for (std::size_t k = 0; k < document["pairs"].size(); ++k) {
    picks.push_back(read_entry(document["pairs"][k], file, "pairs[" + std::to_string(k) + "]"));
  }
  return picks;
}

}  // namespace scanbench::app
