// Reading a range / intensity / color image triplet: the native output of a
// panoramic scanner such as the RIEGL LMS-Z360, three images on one
// rows × columns grid plus a JSON sidecar that ties them together.
//
// Sidecar schema ("scanbench-triplet", version 1):
//
//   {
//     "format": "scanbench-triplet",          required, exactly this string
//     "version": 1,                           required integer, only 1 is known
//     "name": "lobby",                        optional; default: the sidecar's file stem
//     "scanner": "RIEGL LMS-Z360",            optional; default: "" (unknown)
//     "rows": R, "columns": C,                required integers, 1..1,000,000 each,
//                                             R × C ≤ 2^31
//     "range": {"file": "x_range.tiff", "encoding": "float32"}
//           or {"file": "x_range.png", "encoding": "uint16",
//               "scale_m": 0.001, "offset_m": 0.0},     required
//     "intensity": {"file": "x_intensity.png"},          optional
//     "color": {"file": "x_color.png", "transfer": "srgb"},  optional
//     "angles": {"azimuth_start_rad": .., "azimuth_step_rad": ..,
//                "elevation_start_rad": .., "elevation_step_rad": ..},  required
//     "T_world_scan": [16 numbers, row-major],           required, rigid
//     "scanner_position_world": [x, y, z]                optional [m]; default:
//                                                        translation of T_world_scan
//   }
//
// Image file names are relative to the sidecar's folder (absolute names are
// used as they are) and may be in any format OpenCV reads without conversion.
// Image row r / column c is grid pixel (row r, col c); nothing is flipped.
//
// Channels:
// - range, "float32": one-channel 32-bit float image (TIFF) [m]. NaN, ±inf and
//   values ≤ 0 are "no return".
// - range, "uint16": one-channel 16-bit image. 0 is "no return"; any other v is
//   range_m = offset_m + scale_m · v, computed in double and stored as float.
//   scale_m must be finite and > 0, offset_m finite (default 0). A decoded
//   range ≤ 0 also counts as no return, so that both encodings agree that a
//   valid range is positive.
// - intensity: one channel, 8-bit (v / 255) or 16-bit (v / 65535), stored as
//   float in [0, 1].
// - color: 3 channels (a 4th, alpha, is ignored), 8 or 16 bits per channel,
//   stored as 8-bit R, G, B. 16-bit color is what the scanner records; its
//   display software maps it to 8 bits with a transfer curve named by
//   "transfer":
//     "srgb"   (default) x = v / 65535, then the sRGB encoding curve of
//              IEC 61966-2-1 (12.92·x below 0.0031308, else 1.055·x^(1/2.4) −
//              0.055), then round(255 · y). The sensor is linear in light, so
//              this is what makes the 8-bit image look like a photograph.
//     "linear" round(v / 257), i.e. the top 8 bits, rounded.
//   8-bit color is taken as it is; "transfer" is then ignored.
#pragma once

#include <filesystem>
#include <vector>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Reads the triplet described by `sidecar_json` into a spherical Scan.
//
// Result: rows × columns grid; range_m [m] and valid from the range image
// (invalid pixels hold range 0); intensity / rgb only when the sidecar names
// those images; angles [rad] as given; T_world_scan validated as rigid;
// scanner.name from "scanner", scanner.source_file = the sidecar path (UTF-8),
// scanner.position_world [m] from the key or the pose translation.
//
// Throws InputError, naming the sidecar (with the key, or the JSON byte offset)
// or the offending image, for every malformed input: unreadable, empty or
// non-JSON sidecar, missing or mistyped keys, wrong format or version, absurd
// dimensions, non-finite or zero-step angles, non-rigid pose, bad range
// scale, missing or unreadable images, images of the wrong type or size.
// Nothing is returned partially. Paths may contain spaces and UTF-8.
// `image_files`, when given, receives the images' paths (range, then
// intensity and colour where the sidecar names them).
Scan read_triplet(const std::filesystem::path& sidecar_json,
                  std::vector<std::filesystem::path>* image_files = nullptr);

}  // namespace scanbench::acquisition
