// A scan too large to hold whole, held a band of rows at a time
// (docs/scale.md, "Big scans"): its channels read from the project by rows
// (store/layer_rows.hpp), the bands in order, the rows two bands share
// (their halos) kept rather than read again.
#pragma once

#include <cstdint>

#include "acquisition/scan.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::modeling {

class ScanRows {
 public:
  // Scan `id` of `project` (which must outlive this), with range, validity
  // and per-pixel directions, and intensity and colour where `channels`
  // asks for them: only channels the scan has (its summary). Throws
  // core::InputError as Project::load_scan does, a layer missing included.
  ScanRows(const store::Project& project, std::int64_t id,
           store::Project::ScanChannels channels = {false, false});

  // The scan without its arrays (its grid size, angle model, pose).
  const acquisition::Scan& description() const { return description_; }

  // The scan's rows [first, end): a Scan of end − first rows with the
  // scan's angle model (per-pixel directions of those rows only). Bands go
  // forward: `first` lies within the last band or at its end, and `end`
  // at or after the last band's end (asserted). Valid until the next call.
  // Throws core::InputError naming the layer when its data is damaged.
  const acquisition::Scan& hold(int first, int end);

 private:
  template <typename T>
  void advance(std::optional<store::LayerRowReader>& reader, std::vector<T>& values,
               std::size_t per_pixel, int first, int end);

  acquisition::Scan description_;
  acquisition::Scan held_;
  int first_ = 0;  // the scan row of held_'s row 0
  std::optional<store::LayerRowReader> range_, valid_, intensity_, rgb_, directions_;
};

}  // namespace scanbench::modeling
