#include "modeling/lod/shown_points.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <optional>

#include "core/errors.hpp"
#include "core/memory.hpp"
#include "modeling/lod/splat_shape.hpp"
#include "modeling/scan_rows.hpp"
#include "modeling/store/layer_rows.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::lod {
namespace {

// A band of a scan's rows with everything the passes read.
struct Band {
  const acquisition::Scan& description;  // the scan without its arrays
  const acquisition::Scan& held;  // the band's rows and a row of context either side the grid has
  int held_first = 0;             // the grid row of held's row 0
  int first = 0, end = 0;         // the band's grid rows
  const acquisition::ScanGeometry& geometry;  // the band's rows
  const std::optional<std::vector<std::uint8_t>>& keep;
  const std::optional<std::vector<std::uint32_t>>& membership;
};

// What a pass reads: the first, what says where the shown points are and
// the intensities; the second, everything.
enum class Reading { kPositions, kEverything };

// Reads scan `stored` band by band.
// Bands of `rows_per_band` rows, or of about `band_pixels` pixels when 0.
void for_each_band(const store::Project& project, const store::StoredScanSummary& stored,
                   Reading reading, std::size_t band_pixels, int rows_per_band,
                   const std::function<void(const Band&)>& visit) {
  const std::int64_t id = stored.id;
  const bool everything = reading == Reading::kEverything;
  modeling::ScanRows rows(project, id,
                          {stored.summary.has_intensity, everything && stored.summary.has_color});
  const acquisition::Scan& description = rows.description();
  // The geometry whole, or its flags alone (which pixels are mixed).
  std::optional<store::GeometryLayerReader> geometry_rows;
  std::optional<store::LayerRowReader> flag_rows;
  if (everything) {
    geometry_rows = store::GeometryLayerReader::open(project, id);
  } else {
    flag_rows = project.open_layer_rows(id, store::layer::kGeometryFlags, store::ElementType::kU8);
  }
  if (!geometry_rows && !flag_rows) {
    refuse_scan(project, stored,
                "has no geometry (footprints and normals): run `scanbench geometry`");
  }
  std::optional<store::LayerRowReader> keep =
      project.open_layer_rows(id, store::layer::kKeep, store::ElementType::kU8);
  std::optional<store::LayerRowReader> membership =
      project.open_layer_rows(id, store::layer::kMembership, store::ElementType::kU32);
  const int band =
      rows_per_band > 0 ? rows_per_band : store::band_rows(band_pixels, description.columns);
  for (int first = 0; first < description.rows; first += band) {
    const int end = std::min(description.rows, first + band);
    const int held_first = std::max(0, first - 1);
    const acquisition::Scan& held = rows.hold(held_first, std::min(description.rows, end + 1));
    acquisition::ScanGeometry geometry;
    if (geometry_rows) {
      geometry = geometry_rows->read(end - first);
    } else {
      geometry.flags = flag_rows->read_rows<std::uint8_t>(end - first);
    }
    const auto kept = store::read_rows<std::uint8_t>(keep, end - first);
    const auto owners = store::read_rows<std::uint32_t>(membership, end - first);
    visit({description, held, held_first, first, end, geometry, kept, owners});
  }
}

// A float's bits in an order that sorts as the floats do.
std::uint32_t sortable(float value) {
  const auto bits = std::bit_cast<std::uint32_t>(value);
  return (bits & 0x80000000u) != 0 ? ~bits : bits | 0x80000000u;
}

float unsortable(std::uint32_t key) {
  return std::bit_cast<float>((key & 0x80000000u) != 0 ? key & 0x7fffffffu : ~key);
}

// Percentiles of a scan's intensities from a histogram of their top 20
// sortable bits: a bin spans 1/2048 of its value, so its middle is within
// 1/4096 of every value in it.
class IntensityHistogram {
 public:
  static constexpr int kDropped = 12;
  IntensityHistogram() : counts_(std::size_t{1} << (32 - kDropped), 0) {}
  void add(float value) {
    if (!std::isfinite(value)) return;
    ++counts_[sortable(value) >> kDropped];
    ++total_;
  }
  // The value of rank floor(share · (n − 1)), as acquisition::intensity_range
  // chooses it; none below two values.
  std::optional<float> at(double share) const {
    if (total_ < 2) return std::nullopt;
    const auto rank = static_cast<std::uint64_t>(share * static_cast<double>(total_ - 1));
    std::uint64_t below = 0;
    for (std::size_t bin = 0; bin < counts_.size(); ++bin) {
      below += counts_[bin];
      if (below > rank) {
        return unsortable(static_cast<std::uint32_t>(bin << kDropped) | (1u << (kDropped - 1)));
      }
    }
    return std::nullopt;
  }

 private:
  std::vector<std::uint32_t> counts_;
  std::uint64_t total_ = 0;
};

// Calls `shown(g, r, c)` for every shown pixel of the band (g: its index
// in the band's arrays, r: its row in held, c: its column), counting into
// `survey`; `in_model(i, g)` first for every in-model pixel (i: its index
// in held).
template <typename InModel, typename Shown>
void visit_band(const Band& band, ScanSurvey& survey, InModel&& in_model, Shown&& shown) {
  const int columns = band.held.columns;
  for (int row = band.first; row < band.end; ++row) {
    const int r = row - band.held_first;
    for (int c = 0; c < columns; ++c) {
      const std::size_t i = band.held.index(r, c);
      const std::size_t g = static_cast<std::size_t>(row - band.first) * columns + c;
      if (!band.held.valid[i] || band.geometry.is_mixed(g)) continue;
      ++survey.in_model;
      in_model(i, g);
      if (band.keep && (*band.keep)[g] == 0) {
        ++survey.merged_away;
      } else if (band.membership && (*band.membership)[g] == store::kDeletedPoints) {
        ++survey.deleted;
      } else {
        ++survey.shown;
        shown(g, r, c);
      }
    }
  }
}

// Where a scan's samples go in the cube: quanta from its corner, the same
// for both passes.
struct Placement {
  const store::Project& project;
  const store::StoredScanSummary& stored;
  const OctreeCube& cube;
  const Eigen::Vector3d& origin;

  // Sample (r, c) of band.held. Throws core::InputError naming the scan when
  // it lies outside the cube (outside the bounds the scan recorded).
  std::array<std::uint32_t, 3> at(const Band& band, const ScanSplats& directions, int r,
                                  int c) const {
    const double range = band.held.range_m[band.held.index(r, c)];
    const Eigen::Vector3d world = stored.summary.T_world_scan *
                                  (range * directions.direction(band.held, band.held_first, r, c));
    const auto q = cube.quantize(world - origin);
    if (!q)
      refuse_scan(project, stored,
                  "has a point outside its recorded bounds: run `scanbench check`");
    return *q;
  }
};

// What the store keeps of sample i of `held` besides where it is and
// whose: its intensity on the scan's spread, its recorded colour and its
// splat.
void describe_sample(const acquisition::Scan& held, std::size_t i, const LodScan& scan,
                     const Splat& splat, LodPoint& p) {
  const float spread =
      scan.intensity_high > scan.intensity_low ? scan.intensity_high - scan.intensity_low : 1.0f;
  const float level =
      held.has_intensity() && std::isfinite(held.intensity[i])
          ? std::clamp((held.intensity[i] - scan.intensity_low) / spread, 0.0f, 1.0f)
          : 0.5f;
  p.intensity = static_cast<std::uint8_t>(std::lround(255.0f * level));
  if (held.has_color()) {
    p.flags |= LodPoint::kHasColor;
    p.rgb = {held.rgb[3 * i], held.rgb[3 * i + 1], held.rgb[3 * i + 2], 0};
  }
  if (!splat.normal.isZero()) {
    p.flags |= LodPoint::kHasNormal;
    p.normal = encode_unit(splat.normal);
  }
  if (splat.major_axis.isZero()) {
    p.flags |= LodPoint::kRound;
  } else {
    p.major_axis = encode_unit(splat.major_axis);
  }
  p.radii = {to_half(splat.radii_m.x()), to_half(splat.radii_m.y())};
}

}  // namespace

void refuse_scan(const store::Project& project, const store::StoredScanSummary& stored,
                 const std::string& problem) {
  core::FilePosition position;
  position.detail = "scan " + std::to_string(stored.id) + " (" + stored.summary.name + ")";
  throw core::InputError(project.path().string(), position, problem);
}

ScanSurvey survey_scan(
    const store::Project& project, const store::StoredScanSummary& stored, const OctreeCube& cube,
    const Eigen::Vector3d& origin, const ShownPointsSettings& settings,
    const std::function<void(std::span<const std::array<std::uint32_t, 3>>)>& visit) {
  ScanSurvey survey;
  const Placement place{project, stored, cube, origin};
  IntensityHistogram intensities;
  std::vector<std::array<std::uint32_t, 3>> positions;
  std::optional<ScanSplats> directions;
  for_each_band(project, stored, Reading::kPositions, settings.band_pixels, 0,
                [&](const Band& band) {
                  if (!directions) {
                    directions.emplace(band.description, settings.max_stretch);
                    survey.band_rows = band.end - band.first;
                  }
                  positions.clear();
                  const bool has_intensity = band.held.has_intensity();
                  visit_band(
                      band, survey,
                      [&](std::size_t i, std::size_t) {
                        if (has_intensity) intensities.add(band.held.intensity[i]);
                      },
                      [&](std::size_t, int r, int c) {
                        if (visit) positions.push_back(place.at(band, *directions, r, c));
                      });
                  if (visit) visit(positions);
                });
  if (const auto low = intensities.at(0.02)) {
    survey.intensity_low = *low;
    survey.intensity_high = *intensities.at(0.98);
  }
  return survey;
}

void read_shown_bands(const store::Project& project, const store::StoredScanSummary& stored,
                      const LodScan& scan, const OctreeCube& cube, const Eigen::Vector3d& origin,
                      const ShownPointsSettings& settings,
                      const std::function<void(const ShownBand&)>& visit) {
  ScanSurvey counts;
  const Placement place{project, stored, cube, origin};
  std::vector<std::uint32_t> owners;
  std::optional<ScanSplats> splats;
  for_each_band(project, stored, Reading::kEverything, 0, scan.digest_rows, [&](const Band& band) {
    const acquisition::Scan& held = band.held;
    const int columns = held.columns;
    if (!splats) splats.emplace(band.description, settings.max_stretch);
    owners.assign(static_cast<std::size_t>(band.end - band.first) * columns, kNotInModel);
    visit_band(
        band, counts,
        [&](std::size_t, std::size_t g) { owners[g] = shown_owner(band.keep, band.membership, g); },
        [](std::size_t, int, int) {});
    const auto point = [&](std::size_t g) {
      const int r = band.first + static_cast<int>(g / columns) - band.held_first;
      const int c = static_cast<int>(g % columns);
      const std::size_t i = held.index(r, c);
      BuildPoint p;
      p.point.offset = place.at(band, *splats, r, c);
      p.point.pixel = static_cast<std::uint32_t>(static_cast<std::size_t>(band.held_first + r) *
                                                     static_cast<std::size_t>(columns) +
                                                 static_cast<std::size_t>(c));
      p.priority = point_priority(stored.id, p.point.pixel);
      p.point.scan = scan.index;
      p.point.object = owners[g];
      describe_sample(held, i, scan, splats->splat(held, band.held_first, band.geometry, g, r, c),
                      p.point);
      return p;
    };
    visit({band.first, band.end, columns, owners, point});
  });
}

void read_owner_layers(
    const store::Project& project, const store::StoredScanSummary& stored, int rows_per_band,
    const std::function<void(int, int, const std::optional<std::vector<std::uint8_t>>&,
                             const std::optional<std::vector<std::uint32_t>>&)>& visit) {
  std::optional<store::LayerRowReader> keep =
      project.open_layer_rows(stored.id, store::layer::kKeep, store::ElementType::kU8);
  std::optional<store::LayerRowReader> membership =
      project.open_layer_rows(stored.id, store::layer::kMembership, store::ElementType::kU32);
  const int rows = stored.summary.rows;
  for (int first = 0; first < rows; first += rows_per_band) {
    const int end = std::min(rows, first + rows_per_band);
    visit(first, end, store::read_rows<std::uint8_t>(keep, end - first),
          store::read_rows<std::uint32_t>(membership, end - first));
  }
}

namespace {

// The layers that place and describe a point; and those that say whether
// it is shown and whose it is.
constexpr std::array<const char*, 10> kPointLayers = {store::layer::kRange,
                                                      store::layer::kValid,
                                                      store::layer::kIntensity,
                                                      store::layer::kRgb,
                                                      store::layer::kDirections,
                                                      store::layer::kRecordedNormal,
                                                      store::layer::kRecordedFootprint,
                                                      store::layer::kFootprint,
                                                      store::layer::kNormal,
                                                      store::layer::kGeometryFlags};
constexpr std::array<const char*, 2> kOwnerLayers = {store::layer::kKeep,
                                                     store::layer::kMembership};

// "NAME=WHAT;" for each layer, WHAT from `describe` ("-" for none).
template <std::size_t N>
std::string describe_layers(
    const std::array<const char*, N>& names,
    const std::function<std::optional<std::string>(const char*)>& describe) {
  std::string out;
  for (const char* name : names)
    out += std::string(name) + "=" + describe(name).value_or("-") + ";";
  return out;
}

}  // namespace

ScanSources scan_sources(const store::Project& project, std::int64_t scan_id) {
  const auto writer = [&](const char* name) -> std::optional<std::string> {
    const std::optional<store::CommandRecord> record = project.layer_writer(scan_id, name);
    if (!record) return std::nullopt;
    return std::to_string(record->id);
  };
  return {describe_layers(kPointLayers, writer), describe_layers(kOwnerLayers, writer)};
}

std::string scan_points_content(const store::Project& project, std::int64_t scan_id) {
  return describe_layers(
      kPointLayers, [&](const char* name) { return project.layer_fingerprint(scan_id, name); });
}

}  // namespace scanbench::lod
