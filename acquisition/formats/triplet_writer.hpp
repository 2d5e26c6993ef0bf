// Writing a scan as a range / intensity / color image triplet with a JSON
// sidecar; the format and its semantics are documented in triplet_reader.hpp.
#pragma once

#include <filesystem>
#include <vector>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

struct TripletWriteSettings {
  enum class RangeEncoding {
    kFloat32,  // <stem>_range.tiff, 32-bit float: exact for every range
    kUint16,   // <stem>_range.png, range_m = range_offset_m + range_scale_m · v
  };
  RangeEncoding range_encoding = RangeEncoding::kFloat32;
  double range_scale_m = 0.001;  // [m] per count, uint16 only; finite, > 0
  double range_offset_m = 0.0;   // [m] added to every count, uint16 only; finite
};

// Writes `scan` as <stem>.json (= `sidecar_json`) plus, in the same folder,
// <stem>_range.tiff or <stem>_range.png, <stem>_intensity.png (16-bit, only
// when the scan has intensity) and <stem>_color.png (8-bit, only with color).
// Existing files of those names are replaced; the sidecar is written last.
//
// Encoding: invalid pixels, and valid ones whose range is not finite and > 0,
// are written as 0 (no return). float32 keeps every other range bit for bit;
// uint16 rounds (range − offset) / scale to the nearest count. Intensity is
// written as round(clamp(i, 0, 1) · 65535) (NaN → 0). Doubles in the sidecar
// (angles, pose, position) are written so that they read back exactly, so
// read_triplet(write_triplet(read_triplet(x))) reproduces read_triplet(x).
//
// Programmer errors throw std::invalid_argument and write nothing: a scan with
// per-pixel directions (the triplet has only the spherical angle model), an
// empty or inconsistent scan, non-finite or zero-step angles, a non-rigid
// pose, a non-finite scanner position, bad uint16 settings, or a valid range
// that does not fit the uint16 encoding (count outside 1..65535).
// A failure to write a file throws std::runtime_error naming that file.
void write_triplet(const Scan& scan, const std::filesystem::path& sidecar_json,
                   const TripletWriteSettings& settings = {});

// The files write_triplet writes for `scan`: its images, then the sidecar.
std::vector<std::filesystem::path> triplet_files(const Scan& scan,
                                                 const std::filesystem::path& sidecar_json,
                                                 const TripletWriteSettings& settings = {});

}  // namespace scanbench::acquisition
