// Exporting a project's scans or its merged model to the interchange formats
// (acquisition/ writes the files; this decides what goes into them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::modeling {

enum class ExportFormat {
  kPtx,      // scan frame + pose, lossless
  kPly,      // binary PLY, world coordinates, with normals and footprints after geometry
  kCsv,      // text, world coordinates
  kTriplet,  // range/colour/intensity images and a JSON sidecar; one spherical scan
  kLas,      // LAS 1.4, point format 7, world coordinates at 0.1 mm; scan id as point source
  kE57,      // ASTM E57: structured scans in spherical coordinates + pose, with their images
};

// The colours an export writes.
enum class ExportColors {
  kShown,     // as the model shows them: the scans' harmonisation and the objects' edits
  kRecorded,  // as the scanner recorded them
};

struct ExportSettings {
  ExportFormat format = ExportFormat::kPly;
  std::optional<std::int64_t> scan_id;  // only this scan; all scans when empty
  // Only the points of the merged model (`scanbench merge`); PLY, CSV, LAS
  // and E57 (whose grids keep every pixel, the others marked invalid).
  bool merged = false;
  std::filesystem::path output;  // the file (triplet: the .json sidecar)
  ExportColors colors = ExportColors::kShown;
  // Every point (--all): those of hidden objects and deleted ones too. By
  // default the export holds what the model shows.
  bool all_points = false;
  // Replace an existing output file (--force). A project, or a file a scan
  // was imported from, is never replaced.
  bool replace_existing = false;
  // PLY, CSV and LAS read and write each scan a band of rows of about this
  // many pixels at a time (docs/scale.md, "Big scans"): some 200 MB at the
  // default, whatever the scan's size. The file does not depend on it.
  std::size_t band_pixels = std::size_t{1} << 22;
};

struct ExportResult {
  std::size_t scans = 0;
  // The points written: valid (point formats: not mixed) or, with `merged`,
  // kept ones.
  std::size_t points = 0;
  std::size_t hidden = 0;   // left out: owned by a hidden object
  std::size_t deleted = 0;  // left out: deleted in the segmentation
  // What the file could not hold (a LAS names its coordinate system in WKT
  // only), for the user to read.
  std::vector<std::string> notes;
};

// Writes the project's scans as the settings say, all read from one state of
// the project (Project::read_snapshot), one scan at a time: memory holds the
// scan being written, whatever the number of scans (E57 holds the
// project's images too), and for PLY, CSV and LAS only a band of its rows
// (ExportSettings::band_pixels), whatever the scan's size. What the model shows unless the
// settings ask for recorded colours or all points. Points left out are
// marked invalid in the grid formats (PTX, triplet, E57's structured scans)
// and not written in the others. Outputs are checked first
// (refuse_to_replace_inputs): core::InputError, nothing written. Where a scan has geometry,
// the point formats leave its mixed pixels out and PLY carries its normals
// and footprints. Throws core::InputError (naming the project and, where it
// applies, the scan) for: no such scan, `merged` with a scan-grid format or
// before a merge, a triplet of several scans or of a per-pixel scan, LAS of
// a scan whose id does not fit a point source id (above 65535). Output
// is all-or-nothing (acquisition/formats/output_file.hpp); write failures throw
// std::runtime_error naming the file.
// `progress`, when given, gets a unit per scan written and may cancel
// (core::Cancelled, nothing written).
ExportResult export_project(const store::Project& project, const ExportSettings& settings,
                            core::Progress* progress = nullptr);

// Refuses (core::InputError naming the output, nothing written) an output
// that would replace an input of the project: the project itself or one of
// its files, by any path (a symlink, a hard link, "./"), or a file one of
// its scans was imported from (by path, or renamed or linked, by identity:
// acquisition::names_source_file), whatever `replace_existing` says; and,
// unless `replace_existing`, any file that exists. Any other project is
// refused by the output file itself (acquisition/formats/output_file.hpp). Every
// command that writes a file from a project checks its outputs with it
// first.
void refuse_to_replace_inputs(const store::Project& project,
                              std::span<const std::filesystem::path> outputs,
                              bool replace_existing);

}  // namespace scanbench::modeling
