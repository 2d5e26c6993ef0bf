#include "modeling/store/typed_layers.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <utility>

#include "core/errors.hpp"

namespace scanbench::store {
namespace {

// The model at `j` (an object of noise_m, noise_per_m, noise_per_m2), or
// none when it is not one.
std::optional<acquisition::RangeNoise> range_noise_at(const nlohmann::json& j) {
  if (!j.is_object()) return std::nullopt;
  acquisition::RangeNoise noise;
  for (auto [key, term] :
       {std::pair{"noise_m", &noise.noise_m}, std::pair{"noise_per_m", &noise.noise_per_m},
        std::pair{"noise_per_m2", &noise.noise_per_m2}}) {
    const auto value = j.find(key);
    if (value == j.end()) continue;  // a term added later: the default
    if (!value->is_number() || !std::isfinite(value->get<double>()) || value->get<double>() < 0)
      return std::nullopt;
    *term = value->get<double>();
  }
  return noise;
}

// The σ(range) the geometry command `writer` used for scan `id`: its
// result's entry for the scan (the estimate), else its settings' model
// (commands from before the estimate), else the default.
acquisition::RangeNoise recorded_range_noise(const CommandRecord& writer, std::int64_t id) {
  const nlohmann::json result = nlohmann::json::parse(writer.result, nullptr, false);
  if (result.is_object() && result.contains("scans") && result["scans"].is_array()) {
    for (const nlohmann::json& scan : result["scans"]) {
      const auto scan_id = scan.find("id");  // end() for a non-object
      if (scan_id == scan.end() || !scan_id->is_number_integer() ||
          scan_id->get<std::int64_t>() != id) {
        continue;
      }
      if (const auto noise = range_noise_at(scan.value("range_noise", nlohmann::json()))) {
        return *noise;
      }
    }
  }
  const nlohmann::json settings = nlohmann::json::parse(writer.settings, nullptr, false);
  if (settings.is_object()) {
    if (const auto noise = range_noise_at(settings.value("range_noise", nlohmann::json()))) {
      return *noise;
    }
  }
  return {};
}

}  // namespace

std::vector<EncodedLayer> encode_geometry(const acquisition::ScanGeometry& g) {
  std::vector<EncodedLayer> layers;
  layers.push_back(encode_layer<float>(layer::kFootprint, ElementType::kF32, g.footprint_m));
  layers.push_back(encode_layer<Eigen::Vector3f>(layer::kNormal, ElementType::kF32x3, g.normal));
  layers.push_back(encode_layer<float>(layer::kConfidence, ElementType::kF32, g.confidence));
  layers.push_back(encode_layer<std::uint8_t>(layer::kGeometryFlags, ElementType::kU8, g.flags));
  return layers;
}

GeometryLayerWriter::GeometryLayerWriter(int rows, int columns)
    : footprint_(layer::kFootprint, ElementType::kF32, rows, columns),
      normal_(layer::kNormal, ElementType::kF32x3, rows, columns),
      confidence_(layer::kConfidence, ElementType::kF32, rows, columns),
      flags_(layer::kGeometryFlags, ElementType::kU8, rows, columns) {}

void GeometryLayerWriter::write(const acquisition::ScanGeometry& g) {
  footprint_.write(std::span(g.footprint_m));
  normal_.write(std::span(g.normal));
  confidence_.write(std::span(g.confidence));
  flags_.write(std::span(g.flags));
}

void GeometryLayerWriter::put(Project& project, Project::Edit& edit, std::int64_t id) const {
  for (const LayerRowWriter* layer : {&footprint_, &normal_, &confidence_, &flags_})
    project.put_layer(edit, id, *layer);
}

namespace {

// Whether scan `id` has its geometry, from which of its four layers are
// `present`: all of them, or none; throws core::InputError for some.
bool has_geometry(const Project& project, std::int64_t id, int present) {
  if (present == 0) return false;
  if (present != 4) {
    core::FilePosition position;
    position.detail = "scan " + std::to_string(id);
    throw core::InputError(project.path().string(), position,
                           "project is damaged: only some of the geometry layers are stored");
  }
  return true;
}

}  // namespace

std::optional<GeometryLayerReader> GeometryLayerReader::open(const Project& project,
                                                             std::int64_t id) {
  auto footprint = project.open_layer_rows(id, layer::kFootprint, ElementType::kF32);
  auto normal = project.open_layer_rows(id, layer::kNormal, ElementType::kF32x3);
  auto confidence = project.open_layer_rows(id, layer::kConfidence, ElementType::kF32);
  auto flags = project.open_layer_rows(id, layer::kGeometryFlags, ElementType::kU8);
  const int present =
      footprint.has_value() + normal.has_value() + confidence.has_value() + flags.has_value();
  if (!has_geometry(project, id, present)) return std::nullopt;
  return GeometryLayerReader(std::move(*footprint), std::move(*normal), std::move(*confidence),
                             std::move(*flags));
}

GeometryLayerReader::GeometryLayerReader(LayerRowReader footprint, LayerRowReader normal,
                                         LayerRowReader confidence, LayerRowReader flags)
    : footprint_(std::move(footprint)),
      normal_(std::move(normal)),
      confidence_(std::move(confidence)),
      flags_(std::move(flags)) {}

acquisition::ScanGeometry GeometryLayerReader::read(int rows) {
  acquisition::ScanGeometry g;
  g.footprint_m = footprint_.read_rows<float>(rows);
  g.normal = normal_.read_rows<Eigen::Vector3f>(rows);
  g.confidence = confidence_.read_rows<float>(rows);
  g.flags = flags_.read_rows<std::uint8_t>(rows);
  return g;
}

std::optional<acquisition::ScanGeometry> load_geometry(const Project& project, std::int64_t id) {
  auto footprint = project.load_layer<float>(id, layer::kFootprint, ElementType::kF32);
  auto normal = project.load_layer<Eigen::Vector3f>(id, layer::kNormal, ElementType::kF32x3);
  auto confidence = project.load_layer<float>(id, layer::kConfidence, ElementType::kF32);
  auto flags = project.load_layer<std::uint8_t>(id, layer::kGeometryFlags, ElementType::kU8);
  const int present =
      footprint.has_value() + normal.has_value() + confidence.has_value() + flags.has_value();
  if (!has_geometry(project, id, present)) return std::nullopt;
  acquisition::ScanGeometry g;
  g.footprint_m = std::move(*footprint);
  g.normal = std::move(*normal);
  g.confidence = std::move(*confidence);
  g.flags = std::move(*flags);
  if (const std::optional<CommandRecord> writer = project.layer_writer(id, layer::kNormal)) {
    g.range_noise = recorded_range_noise(*writer, id);
  }
  return g;
}

std::vector<EncodedLayer> encode_recorded_geometry(const acquisition::RecordedGeometry& recorded) {
  std::vector<EncodedLayer> layers;
  if (!recorded.normal.empty()) {
    layers.push_back(encode_layer<Eigen::Vector3f>(layer::kRecordedNormal, ElementType::kF32x3,
                                                   recorded.normal));
  }
  if (!recorded.footprint_m.empty()) {
    layers.push_back(
        encode_layer<float>(layer::kRecordedFootprint, ElementType::kF32, recorded.footprint_m));
  }
  return layers;
}

acquisition::RecordedGeometry load_recorded_geometry(const Project& project, std::int64_t id) {
  acquisition::RecordedGeometry recorded;
  if (auto normal =
          project.load_layer<Eigen::Vector3f>(id, layer::kRecordedNormal, ElementType::kF32x3)) {
    recorded.normal = std::move(*normal);
  }
  if (auto footprint =
          project.load_layer<float>(id, layer::kRecordedFootprint, ElementType::kF32)) {
    recorded.footprint_m = std::move(*footprint);
  }
  return recorded;
}

std::optional<std::vector<std::uint8_t>> load_keep_mask(const Project& project, std::int64_t id) {
  return project.load_layer<std::uint8_t>(id, layer::kKeep, ElementType::kU8);
}

}  // namespace scanbench::store
