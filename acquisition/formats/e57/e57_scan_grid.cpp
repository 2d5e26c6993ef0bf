#include "acquisition/formats/e57/e57_scan_grid.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>

#include "acquisition/formats/point_cloud.hpp"
#include "acquisition/local_origin.hpp"
#include "acquisition/spherical_fit.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::uint64_t kBlockRecords = 1u << 16;
constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 30;
// Coordinates (and angles) beyond this are no point of a survey: the
// record counts as no return.
constexpr double kFarthestM = 1e9;

// One field's bytestream, decoded a block of records at a time.
struct FieldStream {
  const E57Field* field = nullptr;
  std::span<const std::byte> bytes;

  explicit operator bool() const { return field != nullptr; }
  // Records first … first + out.size() − 1; the stream's length was checked.
  void decode(std::uint64_t first, std::span<double> out) const {
    [[maybe_unused]] const bool complete = e57_unpack(*field, bytes, first, out);
  }
};

// The fields scanbench reads, by role; absent ones are empty.
struct PointFields {
  bool spherical = false;
  std::array<FieldStream, 3> coordinates;  // range, azimuth, elevation or x, y, z
  FieldStream state, row, column, returns, intensity;
  std::array<FieldStream, 3> color;
};

[[noreturn]] void refuse(const std::filesystem::path& path, const std::string& where,
                         const std::string& problem) {
  core::FilePosition position;
  position.detail = where;
  throw core::InputError(path.string(), position, problem);
}

PointFields point_fields(const std::filesystem::path& path, const E57ScanEntry& entry,
                         const std::vector<std::vector<std::byte>>& streams) {
  const auto find = [&](std::string_view name) {
    for (std::size_t f = 0; f < entry.points.fields.size(); ++f) {
      if (entry.points.fields[f].name == name)
        return FieldStream{&entry.points.fields[f], streams[f]};
    }
    return FieldStream{};
  };
  PointFields fields;
  fields.coordinates = {find("sphericalRange"), find("sphericalAzimuth"),
                        find("sphericalElevation")};
  fields.spherical = fields.coordinates[0] && fields.coordinates[1] && fields.coordinates[2];
  if (!fields.spherical) {
    fields.coordinates = {find("cartesianX"), find("cartesianY"), find("cartesianZ")};
  }
  if (!fields.coordinates[0] || !fields.coordinates[1] || !fields.coordinates[2]) {
    refuse(path, "XML element " + entry.path + "/points/prototype",
           "has neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation");
  }
  fields.state = find(fields.spherical ? "sphericalInvalidState" : "cartesianInvalidState");
  fields.row = find("rowIndex");
  fields.column = find("columnIndex");
  for (const FieldStream* index : {&fields.row, &fields.column}) {
    if (*index && index->field->type != E57FieldType::kInteger) {
      refuse(path, "XML element " + entry.path + "/points/prototype/" + index->field->name,
             "is not an Integer field, as E57 requires of grid indices");
    }
  }
  fields.returns = find("returnIndex");
  fields.intensity = find("intensity");
  fields.color = {find("colorRed"), find("colorGreen"), find("colorBlue")};
  if (!fields.color[0] || !fields.color[1] || !fields.color[2]) fields.color = {};
  return fields;
}

// A block of decoded records; the vectors of absent fields stay empty.
struct Block {
  std::uint64_t first = 0;
  std::size_t count = 0;
  std::array<std::vector<double>, 3> coordinates;
  std::vector<std::uint8_t> state;  // 0 a return, 1 a direction only, 2 nothing
  std::vector<double> row, column, returns, intensity;
  std::array<std::vector<double>, 3> color;
};

void decode_into(const FieldStream& field, const Block& block, std::vector<double>& out) {
  if (!field) return;
  out.resize(block.count);
  field.decode(block.first, out);
}

// Decodes records [first, first + count) into `block`, reusing its buffers.
void decode_block(const PointFields& fields, std::uint64_t first, std::size_t count, Block& block,
                  std::vector<double>& scratch) {
  block.first = first;
  block.count = count;
  for (int k = 0; k < 3; ++k) decode_into(fields.coordinates[k], block, block.coordinates[k]);
  decode_into(fields.row, block, block.row);
  decode_into(fields.column, block, block.column);
  decode_into(fields.returns, block, block.returns);
  decode_into(fields.intensity, block, block.intensity);
  for (int k = 0; k < 3; ++k) decode_into(fields.color[k], block, block.color[k]);
  scratch.assign(count, 0.0);
  decode_into(fields.state, block, scratch);
  block.state.resize(count);
  const auto& [a, b, c] = block.coordinates;
  for (std::size_t i = 0; i < count; ++i) {
    // 0, 1 or 2 as the file says; anything else (NaN included) is nothing.
    const double said = scratch[i];
    std::uint8_t state = said == 0.0 ? 0 : said == 1.0 ? 1 : 2;
    // A return needs a point off the origin and within 10^9 m of it.
    const bool bounded = std::abs(a[i]) <= kFarthestM && std::abs(b[i]) <= kFarthestM &&
                         std::abs(c[i]) <= kFarthestM;  // false for NaN
    const bool off_origin =
        fields.spherical ? a[i] > 0.0 : a[i] != 0.0 || b[i] != 0.0 || c[i] != 0.0;
    if (state == 0 && !(bounded && off_origin)) state = 2;
    block.state[i] = state;
  }
}

template <typename Visit>
void for_each_block(const PointFields& fields, std::uint64_t records, Visit&& visit) {
  Block block;
  std::vector<double> scratch;
  for (std::uint64_t first = 0; first < records; first += kBlockRecords) {
    decode_block(fields, first, static_cast<std::size_t>(std::min(kBlockRecords, records - first)),
                 block, scratch);
    visit(static_cast<const Block&>(block));
  }
}

Eigen::Vector3d point_of(bool spherical, double a, double b, double c) {
  if (!spherical) return {a, b, c};
  const double cos_c = std::cos(c);
  return a * Eigen::Vector3d(cos_c * std::cos(b), cos_c * std::sin(b), std::sin(c));
}

// Maps a channel's values onto [0, 1]: through the scan's limits when it
// gives them, else the field's own bounds when finite, else `fallback`.
struct UnitScale {
  UnitScale(double low_, double high_) : low(low_), inverse_span(1.0 / (high_ - low_)) {}
  // In [0, 1]; 0 for NaN.
  double operator()(double v) const {
    const double t = (v - low) * inverse_span;
    return t > 0.0 ? std::min(t, 1.0) : 0.0;
  }
  double low;
  double inverse_span;
};

UnitScale unit_scale(const E57Field* field, const std::optional<std::pair<double, double>>& limits,
                     UnitScale fallback) {
  if (limits && limits->second > limits->first) return {limits->first, limits->second};
  if (field == nullptr) return fallback;
  if (field->type == E57FieldType::kFloat) {
    const bool bounded = std::isfinite(field->float_minimum) &&
                         std::isfinite(field->float_maximum) &&
                         field->float_maximum > field->float_minimum;
    return bounded ? UnitScale{field->float_minimum, field->float_maximum} : fallback;
  }
  constexpr std::int64_t kExact = std::int64_t{1} << 53;
  if (field->maximum >= kExact || field->minimum <= -kExact || field->maximum == field->minimum) {
    return fallback;
  }
  const double a = static_cast<double>(field->minimum) * field->scale + field->offset;
  const double b = static_cast<double>(field->maximum) * field->scale + field->offset;
  return {std::min(a, b), std::max(a, b)};
}

// The scales of intensity and the three colours.
struct ChannelScales {
  UnitScale intensity{0.0, 1.0};
  std::array<UnitScale, 3> color{UnitScale{0.0, 255.0}, UnitScale{0.0, 255.0},
                                 UnitScale{0.0, 255.0}};
};

ChannelScales channel_scales(const E57ScanEntry& entry, const PointFields& fields) {
  ChannelScales scales;
  scales.intensity = unit_scale(fields.intensity.field, entry.intensity_limits, {0.0, 1.0});
  for (int c = 0; c < 3; ++c) {
    std::optional<std::pair<double, double>> limits;
    if (entry.color_limits) limits = (*entry.color_limits)[c];
    scales.color[c] = unit_scale(fields.color[c].field, limits, {0.0, 255.0});
  }
  return scales;
}

// Copies each record i of `block` with a pixel (pixel[i] ≥ 0) into that
// pixel's validity, intensity and colour; one channel at a time.
void fill_pixels(const Block& block, std::span<const std::int64_t> pixel,
                 const ChannelScales& scales, Scan& scan) {
  for (std::size_t i = 0; i < block.count; ++i) {
    if (pixel[i] >= 0) scan.valid[pixel[i]] = block.state[i] == 0;
  }
  if (scan.has_intensity()) {
    for (std::size_t i = 0; i < block.count; ++i) {
      if (pixel[i] >= 0) {
        scan.intensity[pixel[i]] = static_cast<float>(scales.intensity(block.intensity[i]));
      }
    }
  }
  if (!scan.has_color()) return;
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < block.count; ++i) {
      if (pixel[i] < 0) continue;
      scan.rgb[3 * pixel[i] + c] =
          static_cast<std::uint8_t>(255.0 * scales.color[c](block.color[c][i]) + 0.5);
    }
  }
}

// The grid's index range: the file's index bounds, else the indices' own.
struct IndexRange {
  std::int64_t row_min = 0, row_max = -1, col_min = 0, col_max = -1;
};

// An index as an integer, clamped to ±2^62 (far beyond any grid, so that
// the bounds check refuses it, and differences cannot overflow).
std::int64_t index_value(double v) {
  constexpr double kLimit = 4.611686018427387904e18;  // 2^62
  return static_cast<std::int64_t>(std::clamp(v, -kLimit, kLimit));
}

// The number of indices from lo to hi, 0 when hi < lo.
std::uint64_t extent(std::int64_t lo, std::int64_t hi) {
  return hi < lo ? 0 : static_cast<std::uint64_t>(hi) - static_cast<std::uint64_t>(lo) + 1;
}

IndexRange index_range(const E57ScanEntry& entry, const PointFields& fields) {
  if (entry.index_bounds) {
    const E57IndexBounds& b = *entry.index_bounds;
    const auto clamp = [](std::int64_t v) { return index_value(static_cast<double>(v)); };
    return {clamp(b.row_minimum), clamp(b.row_maximum), clamp(b.column_minimum),
            clamp(b.column_maximum)};
  }
  IndexRange range{
      std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min(),
      std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min()};
  std::vector<double> rows(kBlockRecords), columns(kBlockRecords);
  for (std::uint64_t first = 0; first < entry.points.record_count; first += kBlockRecords) {
    const std::size_t count = std::min(kBlockRecords, entry.points.record_count - first);
    fields.row.decode(first, std::span(rows).first(count));
    fields.column.decode(first, std::span(columns).first(count));
    for (std::size_t i = 0; i < count; ++i) {
      range.row_min = std::min(range.row_min, index_value(rows[i]));
      range.row_max = std::max(range.row_max, index_value(rows[i]));
      range.col_min = std::min(range.col_min, index_value(columns[i]));
      range.col_max = std::max(range.col_max, index_value(columns[i]));
    }
  }
  return range;
}

// The file's coordinates of each pixel's record: x, y, z in three arrays,
// or (spherical) the range in the scan's range channel, which holds it as
// the scan will, and azimuth and elevation in two arrays.
struct PixelCoordinates {
  bool spherical = false;
  std::array<std::vector<double>, 3> values;  // spherical: values[0] unused

  PixelCoordinates(bool spherical_, std::size_t pixels) : spherical(spherical_) {
    for (int k = spherical ? 1 : 0; k < 3; ++k) values[k].assign(pixels, 0.0);
  }
  void set(std::size_t p, const Block& block, std::size_t i, Scan& scan) {
    if (spherical) scan.range_m[p] = static_cast<float>(block.coordinates[0][i]);
    for (int k = spherical ? 1 : 0; k < 3; ++k) values[k][p] = block.coordinates[k][i];
  }
  Eigen::Vector3d point(std::size_t p, const Scan& scan) const {
    return spherical ? point_of(true, scan.range_m[p], values[1][p], values[2][p])
                     : Eigen::Vector3d(values[0][p], values[1][p], values[2][p]);
  }
};

// Sets the scan's angle model and ranges from the coordinates of its
// pixels: a regular spherical grid straight from the file's angles when
// they are one, else through points (local_origin.hpp).
void set_grid(const PixelCoordinates& pixels, Scan& scan) {
  if (pixels.spherical) {
    const SphericalFitResult fit = fit_spherical_angles_to_angles(
        scan.rows, scan.columns, pixels.values[1], pixels.values[2], scan.range_m, scan.valid);
    if (fit.regular) {
      scan.angles = fit.angles;
      for (std::size_t p = 0; p < scan.pixel_count(); ++p) {
        if (!scan.valid[p]) scan.range_m[p] = 0.0f;
      }
      return;
    }
  }
  std::vector<Eigen::Vector3d> points(scan.pixel_count(), Eigen::Vector3d::Zero());
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (scan.valid[p]) points[p] = pixels.point(p, scan);
  }
  set_grid_from_points(scan, points, std::nullopt);
}

// Records with a return gathered compactly, in the file's order, with their
// channels: what becomes a scattered scan, which keeps every one (scan.hpp).
class Returns {
 public:
  Returns(const PointFields& fields, const ChannelScales& scales)
      : fields_(fields),
        scales_(scales),
        channels_(make_empty_scan(0, 0, static_cast<bool>(fields.intensity),
                                  static_cast<bool>(fields.color[0]))) {}

  void reserve(std::uint64_t records) { points_.reserve(scattered_pixel_count(records)); }
  std::size_t size() const { return points_.size(); }

  // Adds the records of `block` that `take` (a record's index in the block)
  // accepts and that have a return.
  template <typename Take>
  void add(const Block& block, const Take& take) {
    slot_.assign(block.count, -1);
    for (std::size_t i = 0; i < block.count; ++i) {
      if (block.state[i] != 0 || !take(i)) continue;
      slot_[i] = static_cast<std::int64_t>(points_.size());
      points_.push_back(point_of(fields_.spherical, block.coordinates[0][i],
                                 block.coordinates[1][i], block.coordinates[2][i]));
    }
    channels_.valid.resize(points_.size());
    if (fields_.intensity) channels_.intensity.resize(points_.size());
    if (fields_.color[0]) channels_.rgb.resize(3 * points_.size());
    fill_pixels(block, slot_, scales_, channels_);
  }

  // The scattered scans of the returns gathered (point_cloud.hpp: one, or
  // tiles of a cloud too wide for one). Throws core::InputError naming
  // `path` when there is none.
  std::vector<ImportedScan> scans(const std::filesystem::path& path) && {
    PointCloud cloud;
    cloud.points = std::move(points_);
    cloud.intensity = std::move(channels_.intensity);
    cloud.rgb = std::move(channels_.rgb);
    return scattered_scans(std::move(cloud), path);
  }

 private:
  const PointFields& fields_;
  const ChannelScales& scales_;
  std::vector<Eigen::Vector3d> points_;
  Scan channels_;
  std::vector<std::int64_t> slot_;  // of each record of a block in the compact arrays
};

// The grid of a structured scan, then, when some records with a return
// found no pixel of their own, the scattered scan that keeps them.
std::vector<ImportedScan> structured_scan(const std::filesystem::path& path,
                                          const E57ScanEntry& entry, const PointFields& fields) {
  const IndexRange range = index_range(entry, fields);
  const std::uint64_t rows = extent(range.row_min, range.row_max);
  const std::uint64_t columns = extent(range.col_min, range.col_max);
  // A grid far larger than its records is a damaged bound, not a scan.
  const std::uint64_t most =
      std::min(kMaxPixels, std::max<std::uint64_t>(16 * entry.points.record_count, 1u << 24));
  if (rows > (1u << 30) || columns > (1u << 30) || rows * columns > most) {
    refuse(path, entry.path,
           "has index bounds of " + std::to_string(rows) + " × " + std::to_string(columns) +
               " pixels for " + std::to_string(entry.points.record_count) +
               " records (at most 16 pixels per record, and 2^30 in all)");
  }
  // The scan's channels, the file's coordinates per pixel, and points
  // where the grid is not a regular panorama: about 64 bytes per pixel.
  core::check_memory(rows * columns * 64, path.string());
  std::vector<ImportedScan> out(1);
  Scan& scan = out[0].scan;
  scan = make_empty_scan(static_cast<int>(rows), static_cast<int>(columns),
                         static_cast<bool>(fields.intensity), static_cast<bool>(fields.color[0]));
  const ChannelScales scales = channel_scales(entry, fields);
  PixelCoordinates pixels(fields.spherical, scan.pixel_count());
  std::vector<std::uint8_t> taken(scan.pixel_count(), 0);
  std::vector<std::int64_t> pixel;
  Returns unplaced(fields, scales);
  for_each_block(fields, entry.points.record_count, [&](const Block& block) {
    pixel.assign(block.count, -1);
    bool any_unplaced = false;
    for (std::size_t i = 0; i < block.count; ++i) {
      const std::int64_t r = index_value(block.row[i]) - range.row_min;
      const std::int64_t c = index_value(block.column[i]) - range.col_min;
      if (r < 0 || c < 0 || r >= scan.rows || c >= scan.columns) {
        refuse(path, "record " + std::to_string(block.first + i) + " of " + entry.path,
               "has row " + std::to_string(index_value(block.row[i])) + ", column " +
                   std::to_string(index_value(block.column[i])) +
                   " outside the scan's index bounds");
      }
      const std::int64_t p = r * scan.columns + c;
      const bool later_return = !block.returns.empty() && block.returns[i] > 0;
      if (later_return || taken[p]) {
        ++out[0].source.unplaced_points;
        any_unplaced = true;
        continue;
      }
      taken[p] = 1;
      pixel[i] = p;
      pixels.set(static_cast<std::size_t>(p), block, i, scan);
    }
    fill_pixels(block, pixel, scales, scan);
    if (any_unplaced && unplaced.size() == 0) {
      // Up to every record but a pixel's first: a point and its channels
      // each, and their scattered scan.
      core::check_memory(entry.points.record_count * 64, path.string());
    }
    if (any_unplaced) unplaced.add(block, [&pixel](std::size_t i) { return pixel[i] < 0; });
  });
  set_grid(pixels, scan);
  if (unplaced.size() > 0) {
    for (ImportedScan& part : std::move(unplaced).scans(path)) out.push_back(std::move(part));
  }
  return out;
}

// The scattered scan of an unstructured entry (or its tiles).
std::vector<ImportedScan> unstructured_scan(const std::filesystem::path& path,
                                            const E57ScanEntry& entry, const PointFields& fields) {
  // Each point in double, its channels, and the scattered scan's own
  // channels and directions: about 64 bytes per record.
  core::check_memory(entry.points.record_count * 64, path.string());
  const ChannelScales scales = channel_scales(entry, fields);
  Returns returns(fields, scales);
  returns.reserve(entry.points.record_count);
  for_each_block(fields, entry.points.record_count,
                 [&](const Block& block) { returns.add(block, [](std::size_t) { return true; }); });
  if (returns.size() == 0) {
    throw core::InputError(path.string(), {{}, {}, "scan \"" + entry.name + "\""},
                           "an unstructured scan with no valid point: there is nothing to import");
  }
  std::vector<ImportedScan> out = std::move(returns).scans(path);
  if (out.size() == 1) out[0].source.points_in_file = entry.points.record_count;
  return out;
}

}  // namespace

std::vector<ImportedScan> scans_from_records(const std::filesystem::path& path,
                                             const E57ScanEntry& entry, std::size_t index,
                                             const std::vector<std::vector<std::byte>>& streams) {
  const PointFields fields = point_fields(path, entry, streams);
  const bool structured = fields.row && fields.column;
  std::vector<ImportedScan> out;
  const std::string name =
      entry.name.empty() ? path.stem().string() + "#" + std::to_string(index) : entry.name;
  if (structured) {
    out = structured_scan(path, entry, fields);
    out[0].source.points_in_file = entry.points.record_count;
    out[0].scan.name = name;
    name_tiles(std::span(out).subspan(1), name + "-unplaced");
  } else {
    out = unstructured_scan(path, entry, fields);
    name_tiles(out, name);
  }
  for (ImportedScan& part : out) {
    Scan& scan = part.scan;
    scan.scanner.name = entry.sensor_model;
    scan.scanner.source_file = path.string();
    scan.scanner.position_world = entry.pose.translation();
    // The grid's local origin (set_grid_from_points) already moved the pose.
    scan.T_world_scan = entry.pose * scan.T_world_scan;
    part.source.format = "e57";
    // Unique per part: the entry's, with the part's suffix ("-unplaced", "-2").
    if (!entry.guid.empty()) part.source.guid = entry.guid + scan.name.substr(name.size());
  }
  return out;
}

}  // namespace scanbench::acquisition
