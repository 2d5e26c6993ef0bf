// Writing ASTM E2807 (E57) files: each scan as a structured scan (rowIndex,
// columnIndex) in spherical coordinates, the range as a ScaledInteger of
// 0.1 mm and the angles as doubles, with intensity, colour, the invalid
// state of every pixel, the pose, index bounds, limits, GUIDs and the
// scan's images. Every pixel of a grid is one record, so that a reader
// gets the grid back whole; a scattered scan (scan.hpp) is written as an
// unstructured one, without indices, one record per point.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

struct E57ScanOutput {
  const Scan* scan = nullptr;
  std::string guid;               // the scan's data3D guid; a new one when empty
  std::vector<ScanImage> images;  // written with associatedData3DGuid = guid
  // When given (one byte per pixel), only these pixels are written as
  // valid: the merged model's points.
  const std::vector<std::uint8_t>* keep = nullptr;
};

// Writes `scans` and the images tied to none (`loose_images`) to `path`,
// with `coordinate_metadata` (the coordinate reference system) in the XML,
// through an OutputFile (a .partial file renamed when complete). A valid
// pixel has sphericalInvalidState 0; a pixel without a return 1 when its
// direction is known (always, for the spherical angle model), else 2.
// Throws core::InputError for a range beyond 400 km (the ScaledInteger's
// bound) and as OutputFile.
void write_e57(const std::filesystem::path& path, std::span<const E57ScanOutput> scans,
               std::span<const ScanImage> loose_images,
               const std::string& coordinate_metadata = "");

// The same file as write_e57, written one scan at a time so that an export
// holds one scan in memory: only the scans' entries in the XML section
// accumulate until commit().
class E57Writer {
 public:
  // Starts the file (an OutputFile: nothing replaces `path` before commit).
  E57Writer(const std::filesystem::path& path, std::string coordinate_metadata);
  ~E57Writer();
  E57Writer(const E57Writer&) = delete;
  E57Writer& operator=(const E57Writer&) = delete;

  // Writes the scan's points and images; the scan may be let go after.
  // Throws as write_e57.
  void add(const E57ScanOutput& scan);
  // Writes the images tied to no scan, the XML section and the header, and
  // replaces the target.
  void commit(std::span<const ScanImage> loose_images);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A new random GUID in the braced form E57 files use.
std::string new_e57_guid();

// A GUID in the same form named by `identity`: the same text always gives
// the same GUID (a name-based one, version 5's layout, from two 64-bit
// FNV-1a hashes rather than SHA-1), different texts different ones.
std::string e57_guid_from(std::string_view identity);

}  // namespace scanbench::acquisition
