// A point of the level-of-detail store (docs/lod.md): 40 bytes, the form a
// node keeps on disk and the renderer uploads as is. Position in quanta of
// 0.1 mm from its node's corner; normal and splat axis octahedral in 2 ×
// 16 bits (within 0.005°); splat radii as IEEE half floats; the colour the
// scan recorded (the shown colour is that through the scan's correction and
// the object's edit, applied when drawing); and where it came from (scan
// and pixel), so edits find it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace scanbench::lod {

struct LodPoint {
  // Flags.
  static constexpr std::uint8_t kHasNormal = 1;  // else a disk facing the eye
  static constexpr std::uint8_t kRound = 2;      // no major axis: radii equal
  static constexpr std::uint8_t kHasColor = 4;   // else grey from intensity

  std::array<std::uint32_t, 3> offset{};  // [quanta] from the node's corner
  std::uint32_t object = 0;               // owning object node id; 0: none
  std::uint32_t pixel = 0;                // row-major index in its scan's grid
  std::uint16_t scan = 0;                 // the store's index of its scan
  std::uint8_t flags = 0;
  std::uint8_t intensity = 0;                // the scan's 2nd–98th percentile spread → 0…255
  std::array<std::int16_t, 2> normal{};      // octahedral, world frame, towards the scanner
  std::array<std::int16_t, 2> major_axis{};  // octahedral, world frame
  std::array<std::uint16_t, 2> radii{};      // half floats [m]: across, along the major axis
  std::array<std::uint8_t, 4> rgb{};         // recorded sRGB; [3] is 0

  bool operator==(const LodPoint&) const = default;
};
static_assert(sizeof(LodPoint) == 40, "the stored form is 40 bytes a point");

// Octahedral encoding of a unit vector (Meyer et al. 2010's map, 16 bits a
// coordinate); decode gives a unit vector.
std::array<std::int16_t, 2> encode_unit(const Eigen::Vector3f& unit);
Eigen::Vector3f decode_unit(const std::array<std::int16_t, 2>& code);

// IEEE 754 binary16, rounded to nearest; finite non-negative inputs (radii)
// saturate at 65504.
std::uint16_t to_half(float value);
float from_half(std::uint16_t half);

// The order in which points compete for a cell: a fixed pseudo-random
// number of the point's identity (the project's scan id and the pixel), so
// that which point a node keeps depends on the points alone.
std::uint64_t point_priority(std::int64_t scan_id, std::uint32_t pixel);

}  // namespace scanbench::lod
