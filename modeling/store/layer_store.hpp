// Per-pixel layers: the one home of every per-pixel array of a scan in the
// project. A layer is a named, typed array with one element per pixel
// (row-major, like the scan), stored as one zstd frame. The scan's channels,
// the geometry and the merge's keep mask are layers; later stages (object
// membership, colour edits) add layers under new names without a schema
// change.
//
// Layer names in use (the types are part of the contract):
//   range_m         f32    range [m] from the scan's local origin
//   valid           u8     1 = a return
//   intensity       f32    only when the scan has intensity
//   rgb             u8x3   only when the scan has colour
//   directions      f32x3  unit directions, per-pixel angle models only
//   recorded_normal f32x3  the normals a scattered scan's file recorded
//                          (acquisition::RecordedGeometry), scan frame
//   recorded_footprint_m f32  the footprints it recorded [m]
//   footprint_m     f32    `scanbench geometry`: footprint radius [m]
//   normal          f32x3  `scanbench geometry`: unit normal, scan frame
//   confidence      f32    `scanbench geometry`
//   geometry_flags  u8     `scanbench geometry`: acquisition::GeometryFlag bits
//   keep            u8     `scanbench merge`: 1 = in the merged model
//   selection       u8     segmentation: 1 = in the selection being grown
//   membership      u32    segmentation: the object node owning the pixel;
//                          0 = still to be segmented, kDeletedPoints = deleted
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace scanbench::store {

// Element types of layers; little-endian, IEEE-754 floats.
enum class ElementType {
  kU8,     // one byte
  kU8x3,   // three bytes (RGB)
  kU32,    // one 32-bit unsigned integer
  kF32,    // one float
  kF32x3,  // three floats (a vector: x, y, z)
};

// "u8", "u8x3", "u32", "f32", "f32x3": the names stored in the project.
const char* element_type_name(ElementType type);
std::optional<ElementType> element_type_from_name(std::string_view name);
// Bytes per element.
std::size_t element_size(ElementType type);

namespace layer {
inline constexpr const char* kRange = "range_m";
inline constexpr const char* kValid = "valid";
inline constexpr const char* kIntensity = "intensity";
inline constexpr const char* kRgb = "rgb";
inline constexpr const char* kDirections = "directions";
inline constexpr const char* kRecordedNormal = "recorded_normal";
inline constexpr const char* kRecordedFootprint = "recorded_footprint_m";
inline constexpr const char* kFootprint = "footprint_m";
inline constexpr const char* kNormal = "normal";
inline constexpr const char* kConfidence = "confidence";
inline constexpr const char* kGeometryFlags = "geometry_flags";
inline constexpr const char* kKeep = "keep";
inline constexpr const char* kSelection = "selection";
inline constexpr const char* kMembership = "membership";
// 1 where a commit carried the pixel into its object from another scan
// (modeling/carried_objects.hpp); meaningful where the membership is set.
inline constexpr const char* kCarried = "carried";
}  // namespace layer

// The membership of points the user deleted (kept in the scan, out of every
// object and of the pool still to be segmented).
inline constexpr std::uint32_t kDeletedPoints = 0xffffffffu;

// A layer compressed and ready to store.
struct EncodedLayer {
  std::string name;
  ElementType type = ElementType::kU8;
  std::size_t element_count = 0;
  std::vector<std::uint8_t> blob;  // one zstd frame of element_count · element_size bytes
};

// Compresses `bytes` (element_count · element_size(type) of them; asserted).
EncodedLayer encode_layer_bytes(std::string name, ElementType type,
                                std::span<const std::byte> bytes);

// Typed form: `values` are the elements' bytes in memory (float for f32,
// Eigen::Vector3f for f32x3, std::uint8_t for u8 and, three per pixel, for
// u8x3). Asserts that they make whole elements.
template <typename T>
EncodedLayer encode_layer(std::string name, ElementType type, std::span<const T> values) {
  return encode_layer_bytes(std::move(name), type, std::as_bytes(values));
}

}  // namespace scanbench::store
