#include "modeling/scan_rows.hpp"

#include <algorithm>
#include <cassert>

#include "core/errors.hpp"

namespace scanbench::modeling {
namespace {

// The reader of a layer the scan must have.
store::LayerRowReader required(const store::Project& project, std::int64_t id, const char* name,
                               store::ElementType type) {
  std::optional<store::LayerRowReader> reader = project.open_layer_rows(id, name, type);
  if (!reader) {  // as Project::load_scan says it
    core::FilePosition position;
    position.detail = "scan " + std::to_string(id);
    throw core::InputError(project.path().string(), position,
                           std::string("project is damaged: layer ") + name + " is missing");
  }
  return std::move(*reader);
}

}  // namespace

ScanRows::ScanRows(const store::Project& project, std::int64_t id,
                   store::Project::ScanChannels channels)
    : description_(project.load_scan_description(id)),
      held_(description_),
      range_(required(project, id, store::layer::kRange, store::ElementType::kF32)),
      valid_(required(project, id, store::layer::kValid, store::ElementType::kU8)) {
  held_.rows = 0;
  if (channels.intensity) {
    intensity_ = required(project, id, store::layer::kIntensity, store::ElementType::kF32);
  }
  if (channels.color) rgb_ = required(project, id, store::layer::kRgb, store::ElementType::kU8x3);
  if (!description_.is_spherical()) {
    directions_ = required(project, id, store::layer::kDirections, store::ElementType::kF32x3);
  }
}

// Drops the rows before `first` from `values` and reads the rows from the
// held ones' end up to `end` (per_pixel values a pixel) from `reader`,
// when there is one.
template <typename T>
void ScanRows::advance(std::optional<store::LayerRowReader>& reader, std::vector<T>& values,
                       std::size_t per_pixel, int first, int end) {
  if (!reader) return;
  const auto row_values = static_cast<std::size_t>(description_.columns) * per_pixel;
  const int held_end = first_ + held_.rows;
  values.erase(values.begin(),
               values.begin() + static_cast<std::ptrdiff_t>((first - first_) * row_values));
  const std::size_t kept = values.size();
  values.resize(kept + static_cast<std::size_t>(end - held_end) * row_values);
  reader->read(std::span(values).subspan(kept));
}

const acquisition::Scan& ScanRows::hold(int first, int end) {
  assert(first >= first_ && first <= first_ + held_.rows && end >= first_ + held_.rows &&
         end <= description_.rows &&
         "bands go forward, each from within or at the end of the last");
  advance(range_, held_.range_m, 1, first, end);
  advance(valid_, held_.valid, 1, first, end);
  advance(intensity_, held_.intensity, 1, first, end);
  advance(rgb_, held_.rgb, 3, first, end);
  if (directions_) {
    advance(directions_, std::get<acquisition::PerPixelDirections>(held_.angles).directions, 1,
            first, end);
  }
  first_ = first;
  held_.rows = end - first;
  return held_;
}

}  // namespace scanbench::modeling
