#include "modeling/store/typed_layers.hpp"

#include "core/errors.hpp"

namespace scanbench::store {

std::vector<EncodedLayer> encode_geometry(const acquisition::ScanGeometry& g) {
  std::vector<EncodedLayer> layers;
  layers.push_back(encode_layer<float>(layer::kFootprint, ElementType::kF32, g.footprint_m));
  layers.push_back(encode_layer<Eigen::Vector3f>(layer::kNormal, ElementType::kF32x3, g.normal));
  layers.push_back(encode_layer<float>(layer::kConfidence, ElementType::kF32, g.confidence));
  layers.push_back(encode_layer<std::uint8_t>(layer::kGeometryFlags, ElementType::kU8, g.flags));
  return layers;
}

std::optional<acquisition::ScanGeometry> load_geometry(const Project& project, std::int64_t id) {
  auto footprint = project.load_layer<float>(id, layer::kFootprint, ElementType::kF32);
  auto normal = project.load_layer<Eigen::Vector3f>(id, layer::kNormal, ElementType::kF32x3);
  auto confidence = project.load_layer<float>(id, layer::kConfidence, ElementType::kF32);
  auto flags = project.load_layer<std::uint8_t>(id, layer::kGeometryFlags, ElementType::kU8);
  const int present =
      footprint.has_value() + normal.has_value() + confidence.has_value() + flags.has_value();
  if (present == 0) return std::nullopt;
  if (present != 4) {
    core::FilePosition position;
    position.detail = "scan " + std::to_string(id);
    throw core::InputError(project.path().string(), position,
                           "project is damaged: only some of the geometry layers are stored");
  }
  acquisition::ScanGeometry g;
  g.footprint_m = std::move(*footprint);
  g.normal = std::move(*normal);
  g.confidence = std::move(*confidence);
  g.flags = std::move(*flags);
  return g;
}

std::optional<std::vector<std::uint8_t>> load_keep_mask(const Project& project, std::int64_t id) {
  return project.load_layer<std::uint8_t>(id, layer::kKeep, ElementType::kU8);
}

}  // namespace scanbench::store
