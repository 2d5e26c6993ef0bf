#include "modeling/export_command.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/formats/e57/e57_writer.hpp"
#include "acquisition/formats/point_export.hpp"
#include "acquisition/formats/ptx_writer.hpp"
#include "acquisition/formats/triplet_writer.hpp"
#include "core/errors.hpp"
#include "core/project_file.hpp"
#include "modeling/color_pipeline.hpp"
#include "modeling/scan_rows.hpp"
#include "modeling/shown_nodes.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {
namespace {

// The exported scans' ids, in id order.
std::vector<std::int64_t> exported_ids(const store::Project& project,
                                       const ExportSettings& settings) {
  std::vector<std::int64_t> ids;
  for (const store::StoredScanSummary& stored : project.scans()) {
    if (!settings.scan_id || stored.id == *settings.scan_id) ids.push_back(stored.id);
  }
  if (settings.scan_id && ids.empty()) {
    throw core::InputError(project.path().string(), {},
                           "no scan with id " + std::to_string(*settings.scan_id));
  }
  return ids;
}

// With `merged`, refuses a grid format, and a scan without a keep mask
// (never merged since its last registration), before anything is loaded.
void check_merged(const store::Project& project, const ExportSettings& settings,
                  const std::vector<std::int64_t>& ids) {
  if (!settings.merged) return;
  const std::string file = project.path().string();
  if (settings.format == ExportFormat::kPtx || settings.format == ExportFormat::kTriplet) {
    throw core::InputError(file, {},
                           "--merged writes the merged model's points: use --format ply, csv, las "
                           "or e57");
  }
  for (const std::int64_t id : ids) {
    const std::vector<std::string> layers = project.layer_names(id);
    if (std::find(layers.begin(), layers.end(), store::layer::kKeep) == layers.end()) {
      throw core::InputError(
          file, {{}, {}, "scan " + std::to_string(id)},
          "no merged model for this scan: run `scanbench merge` after the last registration");
    }
  }
}

// A triplet holds one spherical scan; a PTX holds grids, whose readers take
// neighbouring cells for neighbouring points, which a scattered scan's are
// not. Refused from the summaries, before anything is loaded or written.
void check_grid_format(const store::Project& project, const ExportSettings& settings,
                       const std::vector<const acquisition::ScanSummary*>& summaries) {
  const std::string file = project.path().string();
  if (settings.format == ExportFormat::kTriplet) {
    if (summaries.size() != 1) {
      throw core::InputError(file, {}, "a triplet holds one scan: choose it with --scan ID");
    }
    if (!summaries.front()->spherical) {
      throw core::InputError(file, {{}, {}, "scan \"" + summaries.front()->name + "\""},
                             "a triplet needs the spherical angle model; this scan has per-pixel "
                             "directions (export it as ptx, e57, ply, csv or las)");
    }
  }
  if (settings.format == ExportFormat::kPtx) {
    for (const acquisition::ScanSummary* summary : summaries) {
      if (!summary->scattered) continue;
      throw core::InputError(file, {{}, {}, "scan \"" + summary->name + "\""},
                             "is an unstructured cloud, and a PTX holds scan grids (export it as "
                             "e57, ply, las or csv)");
    }
  }
}

// The coordinate reference system the exported scans' files named: the
// one they share (none when no file named one). Throws core::InputError
// when two scans come from files that name different ones: one E57 file
// holds one system.
std::string common_coordinate_metadata(
    const store::Project& project, const std::vector<std::int64_t>& ids,
    const std::map<std::int64_t, acquisition::ScanSource>& sources) {
  std::string common;
  std::int64_t from = 0;
  for (const std::int64_t id : ids) {
    const auto source = sources.find(id);
    if (source == sources.end() || source->second.coordinate_metadata.empty()) continue;
    if (!common.empty() && source->second.coordinate_metadata != common) {
      throw core::InputError(project.path().string(), {{}, {}, "scan " + std::to_string(id)},
                             "comes from a file in another coordinate system than scan " +
                                 std::to_string(from) + " (\"" +
                                 source->second.coordinate_metadata + "\" and \"" + common +
                                 "\"); export them apart with --scan");
    }
    common = source->second.coordinate_metadata;
    from = id;
  }
  return common;
}

// A guid for a scan that came without one (PTX, a triplet, PCD): derived
// from the project's first command and the scan's id and source, so that
// every export of the project names the scan alike.
std::string derived_guid(const store::Project& project, std::int64_t id,
                         const acquisition::ScanSource* source) {
  const std::vector<store::CommandRecord> history = project.history();
  std::string identity = "scanbench scan " + std::to_string(id);
  if (!history.empty()) identity += " of a project begun " + history.front().created_at;
  if (source != nullptr) {
    identity +=
        " from " + source->format + " (" + std::to_string(source->points_in_file) + " records)";
    if (!source->files.empty()) identity += " at " + source->files.front().path;
  }
  return acquisition::e57_guid_from(identity);
}

// The scans as E57 data3D entries with their guids (kept from an E57
// import, else derived_guid) and images, one scan at a time; the images tied
// to no scan go with a whole-project export only.
class E57Export {
 public:
  E57Export(const store::Project& project, const std::vector<std::int64_t>& ids,
            const ExportSettings& settings)
      : project_(project),
        sources_(project.scan_sources()),
        images_(project.images(true)),
        writer_(settings.output, common_coordinate_metadata(project, ids, sources_)),
        whole_project_(!settings.scan_id) {}

  void add(std::int64_t id, const acquisition::Scan& scan, const std::vector<std::uint8_t>* keep) {
    acquisition::E57ScanOutput output;
    output.scan = &scan;
    const auto source = sources_.find(id);
    const acquisition::ScanSource* from = source != sources_.end() ? &source->second : nullptr;
    output.guid = from && !from->guid.empty() ? from->guid : derived_guid(project_, id, from);
    output.keep = keep;
    for (store::StoredImage& stored : images_) {
      if (stored.scan_id == id) output.images.push_back(std::move(stored.image));
    }
    writer_.add(output);
  }

  void commit() {
    std::vector<acquisition::ScanImage> loose;
    if (whole_project_) {
      for (store::StoredImage& stored : images_) {
        if (!stored.scan_id) loose.push_back(std::move(stored.image));
      }
    }
    writer_.commit(loose);
  }

 private:
  const store::Project& project_;
  std::map<std::int64_t, acquisition::ScanSource> sources_;
  std::vector<store::StoredImage> images_;
  acquisition::E57Writer writer_;
  bool whole_project_;
};

// A scan as the model shows it, unless the settings ask otherwise: colours
// through the scan's correction and the owner's edit, and the points of
// hidden objects and deleted ones left out. A grid format (PTX, a triplet)
// marks them invalid; the others take them out of `keep`, made from the
// valid points where there was none.
class ModelView {
 public:
  ModelView(const store::Project& project, const ExportSettings& settings)
      : settings_(settings),
        tree_(project.object_nodes()),
        shown_(shown_nodes(tree_)),
        colors_(project.scan_color_corrections(), resolve_color_edits(tree_)) {}

  // Whether show() reads the scans' membership (their objects).
  bool wants_membership() const {
    return settings_.colors == ExportColors::kShown || !settings_.all_points;
  }

  // Scan `id` as the model shows it: the points of hidden objects and
  // deleted ones left out (unless every point is exported), the shown
  // colours. `scan` may hold a band of the scan's rows, then `keep` and
  // `membership` are the band's; `membership` is the scan's layer, none
  // where it has none.
  void show(std::int64_t id, acquisition::Scan& scan,
            std::optional<std::vector<std::uint8_t>>& keep,
            const std::optional<std::vector<std::uint32_t>>& membership,
            ExportResult& result) const {
    const bool recolour = settings_.colors == ExportColors::kShown;
    if (!wants_membership()) return;
    const bool grid_format =
        settings_.format == ExportFormat::kPtx || settings_.format == ExportFormat::kTriplet;
    const auto leave_out = [&](std::size_t i) {
      if (grid_format) {
        scan.valid[i] = 0;
        return;
      }
      if (!keep) keep = scan.valid;
      (*keep)[i] = 0;
    };
    for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
      if (!scan.valid[i] || (keep && (*keep)[i] == 0)) continue;
      std::uint32_t owner = membership ? (*membership)[i] : 0;
      if (owner == store::kDeletedPoints) {
        owner = 0;
        if (!settings_.all_points) {
          ++result.deleted;
          leave_out(i);
          continue;
        }
      } else if (owner != 0) {
        const auto found = shown_.find(owner);
        if (found == shown_.end()) {
          owner = 0;  // a node no longer in the tree owns nothing
        } else if (!found->second && !settings_.all_points) {
          ++result.hidden;
          leave_out(i);
          continue;
        }
      }
      if (!recolour || !scan.has_color()) continue;
      std::uint8_t* rgb = &scan.rgb[3 * i];
      const std::array<std::uint8_t, 3> out = colors_.shown(id, owner, {rgb[0], rgb[1], rgb[2]});
      std::copy(out.begin(), out.end(), rgb);
    }
  }

 private:
  const ExportSettings& settings_;
  std::vector<store::ObjectNode> tree_;
  std::map<std::int64_t, bool> shown_;
  ColorPipeline colors_;
};

// The coordinate system for a LAS file, which names it in OGC WKT only;
// anything else the scans' files named becomes a note.
std::string las_wkt(const std::string& coordinate_system, ExportResult& result) {
  if (coordinate_system.empty()) return {};
  if (!acquisition::looks_like_wkt(coordinate_system)) {
    result.notes.push_back("the scans' coordinate system \"" + coordinate_system +
                           "\" is not OGC WKT, which LAS needs: not written (E57 keeps it)");
    return {};
  }
  if (coordinate_system.size() > acquisition::kMaxLasWktBytes) {
    result.notes.push_back("the scans' coordinate system is " +
                           std::to_string(coordinate_system.size()) +
                           " bytes of WKT, more than a LAS record holds: not written (E57 keeps "
                           "it)");
    return {};
  }
  return coordinate_system;
}

// The scans' ids as LAS point source ids (16 bits).
std::vector<std::uint16_t> point_source_ids(const store::Project& project,
                                            const std::vector<std::int64_t>& ids) {
  std::vector<std::uint16_t> out;
  for (const std::int64_t id : ids) {
    if (id > std::numeric_limits<std::uint16_t>::max()) {
      throw core::InputError(project.path().string(), {{}, {}, "scan " + std::to_string(id)},
                             "a LAS point source id holds scan ids up to 65535");
    }
    out.push_back(static_cast<std::uint16_t>(id));
  }
  return out;
}

// The pixels a grid format writes as valid: the valid ones, or the kept.
std::size_t count_points(const acquisition::Scan& scan,
                         const std::optional<std::vector<std::uint8_t>>& keep) {
  const std::vector<std::uint8_t>& counted = keep ? *keep : scan.valid;
  return static_cast<std::size_t>(
      std::count_if(counted.begin(), counted.end(), [](std::uint8_t flag) { return flag != 0; }));
}

// The files a scan imported before sources were recorded names: its path as
// typed then (perhaps relative), taken from the current folder and from the
// project's.
std::vector<acquisition::SourceFile> recorded_source_files(const store::Project& project,
                                                           const std::string& source_file) {
  const std::filesystem::path path(source_file);
  if (path.empty()) return {};
  if (path.is_absolute()) return {acquisition::identify_source_file(path)};
  return {acquisition::identify_source_file(path),
          acquisition::identify_source_file(project.path().parent_path() / path)};
}

// Refuses `output` when it names a file a scan of the project was imported
// from.
void refuse_a_source_file(const store::Project& project,
                          const std::map<std::int64_t, acquisition::ScanSource>& sources,
                          const std::filesystem::path& output) {
  for (const store::StoredScanSummary& scan : project.scans()) {
    const auto source = sources.find(scan.id);
    const std::vector<acquisition::SourceFile> files =
        source != sources.end() && !source->second.files.empty()
            ? source->second.files
            : recorded_source_files(project, scan.summary.scanner.source_file);
    for (const acquisition::SourceFile& file : files) {
      if (!acquisition::names_source_file(output, file)) continue;
      throw core::InputError(output.string(), {},
                             "is a file scan " + std::to_string(scan.id) + " was imported from (" +
                                 file.path +
                                 "); an output never replaces an input of the project, --force "
                                 "or not");
    }
  }
}

}  // namespace

void refuse_to_replace_inputs(const store::Project& project,
                              std::span<const std::filesystem::path> outputs,
                              bool replace_existing) {
  const std::map<std::int64_t, acquisition::ScanSource> sources = project.scan_sources();
  for (const std::filesystem::path& output : outputs) {
    std::error_code error;
    // SQLite's companion files hold the project's latest changes.
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(output, error);
    const std::string project_path = std::filesystem::weakly_canonical(project.path(), error);
    for (const char* suffix : {"-wal", "-shm", "-journal"}) {
      if (canonical == project_path + suffix) {
        throw core::InputError(output.string(), {},
                               "is a file of the project being exported; an export never "
                               "replaces its input");
      }
    }
    if (!std::filesystem::exists(std::filesystem::symlink_status(output, error))) continue;
    if (std::filesystem::equivalent(output, project.path(), error)) {
      throw core::InputError(output.string(), {},
                             "is the project being exported; an export never replaces its input");
    }
    refuse_a_source_file(project, sources, output);
    // Folders, devices and projects get the output file's own refusal.
    const bool replaceable =
        std::filesystem::is_regular_file(output, error) && !core::is_project_file(output);
    if (replaceable && !replace_existing) {
      throw core::InputError(output.string(), {}, "exists; --force replaces it");
    }
  }
}

namespace {

bool is_point_list(ExportFormat format) {
  return format == ExportFormat::kPly || format == ExportFormat::kCsv ||
         format == ExportFormat::kLas;
}

// The channels every exported scan has, from the summaries and the layers'
// names: a point list's columns are fixed before the first scan is loaded.
acquisition::PointChannels common_channels(
    const store::Project& project, const std::vector<std::int64_t>& ids,
    const std::vector<const acquisition::ScanSummary*>& summaries) {
  acquisition::PointChannels channels;
  for (std::size_t s = 0; s < ids.size(); ++s) {
    channels.intensity = channels.intensity && summaries[s]->has_intensity;
    channels.color = channels.color && summaries[s]->has_color;
    const std::vector<std::string> layers = project.layer_names(ids[s]);
    channels.geometry = channels.geometry && std::find(layers.begin(), layers.end(),
                                                       store::layer::kNormal) != layers.end();
  }
  return channels;
}

// LAS's settings: the scans' stored world bounds (their points at the
// current poses) give the offset; the coordinate system as las_wkt.
acquisition::PointListWriter::LasSettings las_settings(
    const store::Project& project, const std::vector<std::int64_t>& ids,
    const std::vector<const acquisition::ScanSummary*>& summaries, ExportResult& result) {
  acquisition::PointListWriter::LasSettings las;
  for (const acquisition::ScanSummary* summary : summaries) {
    if (summary->bbox_world) las.bounds.extend(*summary->bbox_world);
  }
  las.wkt = las_wkt(common_coordinate_metadata(project, ids, project.scan_sources()), result);
  return las;
}

}  // namespace

// Scan `id` shown and added to `points` a band of rows at a time: what
// loading it whole and adding it writes, byte for byte. Cancellable
// between bands (core::Cancelled) through `progress`, when given.
void add_by_bands(const store::Project& project, std::int64_t id, const ModelView& view,
                  const ExportSettings& settings, acquisition::PointChannels channels,
                  std::uint16_t source_id, acquisition::PointListWriter& points,
                  ExportResult& result, core::Progress* progress) {
  using store::ElementType;
  ScanRows rows(project, id, {channels.intensity, channels.color});
  const acquisition::Scan& description = rows.description();
  std::optional<store::GeometryLayerReader> geometry_rows;
  if (channels.geometry) geometry_rows = store::GeometryLayerReader::open(project, id);
  std::optional<store::LayerRowReader> keep, membership;
  if (settings.merged) {  // check_merged made sure there is one
    keep = project.open_layer_rows(id, store::layer::kKeep, ElementType::kU8);
  }
  if (view.wants_membership()) {
    membership = project.open_layer_rows(id, store::layer::kMembership, ElementType::kU32);
  }
  const int band = store::band_rows(settings.band_pixels, description.columns);
  for (int first = 0; first < description.rows; first += band) {
    if (progress != nullptr) progress->throw_if_cancelled("export");
    const int end = std::min(description.rows, first + band), n = end - first;
    acquisition::Scan held = rows.hold(first, end);
    std::optional<acquisition::ScanGeometry> geometry;
    if (geometry_rows) geometry = geometry_rows->read(n);
    std::optional<std::vector<std::uint8_t>> kept = store::read_rows<std::uint8_t>(keep, n);
    view.show(id, held, kept, store::read_rows<std::uint32_t>(membership, n), result);
    points.add(held, geometry ? &*geometry : nullptr, kept ? &*kept : nullptr, source_id, first);
  }
}

ExportResult export_project(const store::Project& project, const ExportSettings& settings,
                            core::Progress* progress) {
  // Masks, poses and channels from one state, whatever commits meanwhile.
  const store::Project::ReadSnapshot snapshot = project.read_snapshot();
  const std::vector<std::int64_t> ids = exported_ids(project, settings);
  const std::vector<store::StoredScanSummary> stored = project.scans();
  std::vector<const acquisition::ScanSummary*> summaries;
  for (const std::int64_t id : ids) {
    const auto found = std::find_if(stored.begin(), stored.end(),
                                    [id](const store::StoredScanSummary& s) { return s.id == id; });
    summaries.push_back(&found->summary);
  }
  check_merged(project, settings, ids);
  check_grid_format(project, settings, summaries);
  std::vector<std::uint16_t> source_ids;
  if (settings.format == ExportFormat::kLas) source_ids = point_source_ids(project, ids);
  // A triplet's files are named after its one scan.
  std::optional<acquisition::Scan> triplet_scan;
  if (settings.format == ExportFormat::kTriplet) triplet_scan = project.load_scan(ids.front());
  const std::vector<std::filesystem::path> outputs =
      triplet_scan ? acquisition::triplet_files(*triplet_scan, settings.output)
                   : std::vector<std::filesystem::path>{settings.output};
  refuse_to_replace_inputs(project, outputs, settings.replace_existing);

  ExportResult result;
  result.scans = ids.size();
  const ModelView view(project, settings);
  // One writer per format; every scan is loaded, shown and written in turn.
  const bool point_list = is_point_list(settings.format);
  std::optional<acquisition::PointListWriter> points;
  acquisition::PointChannels channels;  // of `points`
  std::optional<acquisition::PtxWriter> ptx;
  std::optional<E57Export> e57;
  if (point_list) {
    const acquisition::PointListFormat format =
        settings.format == ExportFormat::kPly   ? acquisition::PointListFormat::kPly
        : settings.format == ExportFormat::kCsv ? acquisition::PointListFormat::kCsv
                                                : acquisition::PointListFormat::kLas;
    const acquisition::PointListWriter::LasSettings las =
        settings.format == ExportFormat::kLas ? las_settings(project, ids, summaries, result)
                                              : acquisition::PointListWriter::LasSettings{};
    channels = common_channels(project, ids, summaries);
    points.emplace(settings.output, format, channels, las);
  } else if (settings.format == ExportFormat::kPtx) {
    ptx.emplace(settings.output);
  } else if (settings.format == ExportFormat::kE57) {
    e57.emplace(project, ids, settings);
  }
  for (std::size_t s = 0; s < ids.size(); ++s) {
    const std::int64_t id = ids[s];
    const std::string& name = summaries[s]->name;
    if (points) {  // a band of rows at a time
      add_by_bands(project, id, view, settings, channels, source_ids.empty() ? 0 : source_ids[s],
                   *points, result, progress);
    } else {  // grids and E57 files are written a scan at a time
      acquisition::Scan scan = triplet_scan ? std::move(*triplet_scan) : project.load_scan(id);
      std::optional<std::vector<std::uint8_t>> keep;
      if (settings.merged) keep = store::load_keep_mask(project, id);
      std::optional<std::vector<std::uint32_t>> membership;
      if (view.wants_membership()) {
        membership = project.load_layer<std::uint32_t>(id, store::layer::kMembership,
                                                       store::ElementType::kU32);
      }
      view.show(id, scan, keep, membership, result);
      result.points += count_points(scan, keep);
      if (ptx) ptx->add(scan);
      if (e57) e57->add(id, scan, keep ? &*keep : nullptr);
      if (settings.format == ExportFormat::kTriplet) triplet_scan = std::move(scan);
    }
    if (progress != nullptr) {
      progress->update({"export", s + 1, ids.size(), name});
      progress->throw_if_cancelled("export");
    }
    // A triplet's files are complete once written: written after the last
    // chance to cancel, as the other formats commit.
    if (triplet_scan) acquisition::write_triplet(*triplet_scan, settings.output);
  }
  if (points) {
    result.points = points->points();
    points->commit();
  }
  if (ptx) ptx->commit();
  if (e57) e57->commit();
  return result;
}

}  // namespace scanbench::modeling
