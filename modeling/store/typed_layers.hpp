// The layers the pipeline's stages write, as the types the algorithms use:
// geometry (footprint, normal, confidence, flags) and the merge's keep mask.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::store {

// The four geometry layers of `geometry` (layer_store.hpp).
std::vector<EncodedLayer> encode_geometry(const acquisition::ScanGeometry& geometry);

// The same layers written a band of rows at a time (layer_rows.hpp), for a
// scan computed band by band.
class GeometryLayerWriter {
 public:
  GeometryLayerWriter(int rows, int columns);
  // The geometry of the next rows, in order (whole rows, asserted).
  void write(const acquisition::ScanGeometry& rows);
  // Stores the four layers of scan `id` as part of `edit`; asserts every
  // row was written.
  void put(Project& project, Project::Edit& edit, std::int64_t id) const;

 private:
  LayerRowWriter footprint_, normal_, confidence_, flags_;
};

// The stored geometry of scan `id` read a band of rows at a time, as
// load_geometry checks it (all four layers or none).
class GeometryLayerReader {
 public:
  // None when the scan has no geometry; throws as load_geometry.
  static std::optional<GeometryLayerReader> open(const Project& project, std::int64_t id);
  // The geometry of the next `rows` rows, in order (no more than remain,
  // asserted); its range_noise is left as it is. Throws as LayerRowReader::read.
  acquisition::ScanGeometry read(int rows);

 private:
  GeometryLayerReader(LayerRowReader footprint, LayerRowReader normal, LayerRowReader confidence,
                      LayerRowReader flags);
  LayerRowReader footprint_, normal_, confidence_, flags_;
};

// The stored geometry of scan `id`, or none when `scanbench geometry` has
// not run on it (or was undone). Its range_noise is the one the command
// that computed it recorded for the scan (its estimate; for commands older
// than estimates, its settings' model). Throws core::InputError naming the
// scan when only some of the four layers are there or one is damaged.
std::optional<acquisition::ScanGeometry> load_geometry(const Project& project, std::int64_t id);

// The layers of what a scattered scan's file recorded (none for what it
// did not), stored with the scan on import.
std::vector<EncodedLayer> encode_recorded_geometry(const acquisition::RecordedGeometry& recorded);

// What the file of scan `id` recorded: empty vectors where it recorded
// nothing (every grid scan). Throws core::InputError naming the scan when a
// layer is damaged.
acquisition::RecordedGeometry load_recorded_geometry(const Project& project, std::int64_t id);

// The merge's keep mask of scan `id` (one byte per pixel, 1 = in the merged
// model), or none when `scanbench merge` has not run since the scan's pose
// or geometry last changed.
std::optional<std::vector<std::uint8_t>> load_keep_mask(const Project& project, std::int64_t id);

}  // namespace scanbench::store
