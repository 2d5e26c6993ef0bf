// Point-list exports of one or more scans in world coordinates: binary PLY
// and CSV. Only valid pixels are written. World coordinates are written in
// double precision: georeferenced sites sit at 10^5–10^6 m.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// `geometry`, when not empty, holds one entry per scan (nullptr where a scan
// has none). When every scan has geometry, its mixed pixels are left out —
// they float between surfaces and belong to no model — and the PLY gains the
// normals and footprints.
//
// `keep`, when not empty, holds one entry per scan: a mask of one byte per
// pixel (1 = write the point; the merged model of `scanbench merge`), or
// nullptr to write every point of that scan.

// Binary little-endian PLY: double x y z, then float intensity when every scan
// has intensity, then uchar red green blue when every scan has colour, then
// float nx ny nz (unit, world frame; 0 0 0 where invalid) and float radius
// (the footprint [m]) when every scan has geometry. All-or-nothing output;
// throws std::runtime_error naming `path` on write errors.
void write_ply(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const ScanGeometry* const> geometry = {},
               std::span<const std::vector<std::uint8_t>* const> keep = {});

// CSV with a header line "x,y,z[,intensity][,r,g,b]" (channel columns as for
// PLY), one valid point per line, shortest exact decimals. All-or-nothing
// output; throws std::runtime_error naming `path` on write errors.
void write_csv(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const ScanGeometry* const> geometry = {},
               std::span<const std::vector<std::uint8_t>* const> keep = {});

// LAS 1.4 (revision 15), point data record format 7: X Y Z as 32-bit
// integers at a 0.1 mm scale, offset at the points' minimum corner (so
// georeferenced coordinates keep 0.1 mm), intensity (× 65535), return 1 of
// 1, RGB (8-bit × 257), the scan's `source_ids` entry as point_source_id.
// When every scan has geometry, four extra bytes fields (float NormalX,
// NormalY, NormalZ in the world frame, and Footprint [m]) described by the
// LASF_Spec extra bytes VLR. The legacy point counts are 0, as the
// specification requires for formats 6–10. A non-empty `wkt` (OGC WKT of
// the coordinate system, at most kMaxLasWktBytes) goes into the
// LASF_Projection 2112 VLR. Throws core::InputError naming `path` when the
// points span more than 0.1 mm × 2³¹ on an axis; All-or-nothing output as
// write_ply.
void write_las(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const std::uint16_t> source_ids,
               std::span<const ScanGeometry* const> geometry = {},
               std::span<const std::vector<std::uint8_t>* const> keep = {},
               std::string_view wkt = {});

// The optional fields of a point-list export, the same for every point.
struct PointChannels {
  bool intensity = true;
  bool color = true;
  // Normals and footprints (PLY, LAS); mixed pixels are left out.
  bool geometry = true;
};

enum class PointListFormat { kPly, kCsv, kLas };

// A PLY, CSV or LAS file written one scan (or one band of a scan's rows) at
// a time, so that an export holds that in memory whatever the size of the
// campaign: the files are those
// of write_ply, write_csv and write_las. The channels are fixed up front (a
// project knows them from its scans' summaries); the counts, and LAS's
// bounds, go into the header at commit().
class PointListWriter {
 public:
  struct LasSettings {
    // A box that holds every point to be written (the scans' world
    // bounds): its minimum is the offset of the quantised coordinates.
    Eigen::AlignedBox3d bounds;
    std::string wkt;  // as write_las
  };
  // Throws core::InputError naming `path` when LAS `bounds` span more than
  // 0.1 mm × 2³¹ on an axis (nothing written), and as OutputFile.
  PointListWriter(const std::filesystem::path& path, PointListFormat format, PointChannels channels,
                  const LasSettings& las = {});
  ~PointListWriter();
  PointListWriter(const PointListWriter&) = delete;
  PointListWriter& operator=(const PointListWriter&) = delete;

  // Writes the scan's exported pixels (valid, kept, not mixed when the
  // channels have geometry), row-major. `geometry` is needed when the
  // channels have geometry, `source_id` is LAS's point source id. Throws
  // core::InputError naming the file and the scan when the scan lacks a
  // channel the file has, or a LAS point falls outside `bounds` by more than
  // its integers hold; as OutputFile on write errors. A scan too large to
  // hold is added a band of rows at a time, in order: `scan` then holds
  // the grid's rows from `first_row` (direction_precise), and `geometry`
  // and `keep` theirs.
  void add(const Scan& scan, const ScanGeometry* geometry,
           const std::vector<std::uint8_t>* keep = nullptr, std::uint16_t source_id = 0,
           int first_row = 0);
  std::size_t points() const;
  // Completes the header and replaces the target (all-or-nothing).
  void commit();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A VLR's length is 16 bits; the WKT is written with its terminating null.
inline constexpr std::size_t kMaxLasWktBytes = 65534;

// Whether `text` reads as OGC WKT (a keyword and a bracket: PROJCS[...,
// GEOGCS[..., PROJCRS[..., COMPOUNDCRS[...), not an "EPSG:N" code or a name.
bool looks_like_wkt(std::string_view text);

}  // namespace scanbench::acquisition
