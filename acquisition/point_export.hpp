// Point-list exports of one or more scans in world coordinates: binary PLY
// and CSV. Only valid pixels are written. World coordinates are written in
// double precision: georeferenced sites sit at 10^5–10^6 m.
#pragma once

#include <filesystem>
#include <span>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Binary little-endian PLY: double x y z, then float intensity when every scan
// has intensity, then uchar red green blue when every scan has colour.
// (Normals and footprints join once the geometry stage computes them.)
// All-or-nothing output; throws std::runtime_error naming `path` on write errors.
void write_ply(const std::filesystem::path& path, std::span<const Scan> scans);

// CSV with a header line "x,y,z[,intensity][,r,g,b]" (channel columns as for
// PLY), one valid point per line, shortest exact decimals. All-or-nothing
// output; throws std::runtime_error naming `path` on write errors.
void write_csv(const std::filesystem::path& path, std::span<const Scan> scans);

}  // namespace scanbench::acquisition
