#include "modeling/export_command.hpp"

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "acquisition/formats/e57/e57_writer.hpp"
#include "acquisition/formats/point_export.hpp"
#include "acquisition/formats/ptx_writer.hpp"
#include "acquisition/formats/triplet_writer.hpp"
#include "core/errors.hpp"
#include "core/project_file.hpp"
#include "modeling/color_pipeline.hpp"
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

// With `merged`, the keep mask of every exported scan; none otherwise.
std::vector<std::vector<std::uint8_t>> keep_masks(const store::Project& project,
                                                  const ExportSettings& settings,
                                                  const std::vector<std::int64_t>& ids) {
  if (!settings.merged) return {};
  const std::string file = project.path().string();
  if (settings.format == ExportFormat::kPtx || settings.format == ExportFormat::kTriplet) {
    throw core::InputError(file, {},
                           "--merged writes the merged model's points: use --format ply, csv, las "
                           "or e57");
  }
  std::vector<std::vector<std::uint8_t>> masks;
  for (const std::int64_t id : ids) {
    std::optional<std::vector<std::uint8_t>> mask = store::load_keep_mask(project, id);
    if (!mask) {
      throw core::InputError(
          file, {{}, {}, "scan " + std::to_string(id)},
          "no merged model for this scan: run `scanbench merge` after the last registration");
    }
    masks.push_back(std::move(*mask));
  }
  return masks;
}

void write_triplet(const store::Project& project, const std::vector<acquisition::Scan>& scans,
                   const ExportSettings& settings) {
  const std::string file = project.path().string();
  if (scans.size() != 1) {
    throw core::InputError(file, {}, "a triplet holds one scan: choose it with --scan ID");
  }
  if (!scans.front().is_spherical()) {
    throw core::InputError(file, {{}, {}, "scan \"" + scans.front().name + "\""},
                           "a triplet needs the spherical angle model; this scan has per-pixel "
                           "directions (export it as ptx, e57, ply, csv or las)");
  }
  acquisition::write_triplet(scans.front(), settings.output);
}

// A PTX holds grids: its readers take neighbouring cells for neighbouring
// points, which a scattered scan's are not.
void write_ptx(const store::Project& project, const std::vector<acquisition::Scan>& scans,
               const ExportSettings& settings) {
  for (const acquisition::Scan& scan : scans) {
    if (scan.is_scattered()) {
      throw core::InputError(project.path().string(), {{}, {}, "scan \"" + scan.name + "\""},
                             "is an unstructured cloud, and a PTX holds scan grids (export it as "
                             "e57, ply, las or csv)");
    }
  }
  acquisition::write_ptx(settings.output, scans);
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
// import, else derived_guid) and images; the images tied to no scan go with a whole-project
// export only.
void write_e57(const store::Project& project, const std::vector<std::int64_t>& ids,
               const std::vector<acquisition::Scan>& scans,
               const std::vector<const std::vector<std::uint8_t>*>& keep,
               const ExportSettings& settings) {
  const std::map<std::int64_t, acquisition::ScanSource> sources = project.scan_sources();
  std::vector<store::StoredImage> images = project.images(true);
  std::vector<acquisition::E57ScanOutput> outputs(scans.size());
  for (std::size_t s = 0; s < scans.size(); ++s) {
    outputs[s].scan = &scans[s];
    const auto source = sources.find(ids[s]);
    const acquisition::ScanSource* from = source != sources.end() ? &source->second : nullptr;
    outputs[s].guid =
        from && !from->guid.empty() ? from->guid : derived_guid(project, ids[s], from);
    if (!keep.empty()) outputs[s].keep = keep[s];
    for (store::StoredImage& stored : images) {
      if (stored.scan_id == ids[s]) outputs[s].images.push_back(std::move(stored.image));
    }
  }
  std::vector<acquisition::ScanImage> loose;
  if (!settings.scan_id) {
    for (store::StoredImage& stored : images) {
      if (!stored.scan_id) loose.push_back(std::move(stored.image));
    }
  }
  acquisition::write_e57(settings.output, outputs, loose,
                         common_coordinate_metadata(project, ids, sources));
}

// The scans as the model shows them, unless the settings ask otherwise:
// colours through the scan's correction and the owner's edit, and the
// points of hidden objects and deleted ones left out. A grid format (PTX,
// a triplet) marks them invalid; the others take them out of `keep`, made
// from the valid points where there was none.
void show_as_the_model_does(const store::Project& project, const std::vector<std::int64_t>& ids,
                            const ExportSettings& settings, std::vector<acquisition::Scan>& scans,
                            std::vector<std::vector<std::uint8_t>>& keep, ExportResult& result) {
  const bool recolour = settings.colors == ExportColors::kShown;
  if (!recolour && settings.all_points) return;
  const std::vector<store::ObjectNode> tree = project.object_nodes();
  const std::map<std::int64_t, bool> shown = shown_nodes(tree);
  const ColorPipeline colors(project.scan_color_corrections(), resolve_color_edits(tree));
  const bool grid_format =
      settings.format == ExportFormat::kPtx || settings.format == ExportFormat::kTriplet;
  const auto leave_out = [&](std::size_t s, std::size_t i) {
    if (grid_format) {
      scans[s].valid[i] = 0;
      return;
    }
    if (keep.empty()) {
      for (const acquisition::Scan& scan : scans) keep.push_back(scan.valid);
    }
    keep[s][i] = 0;
  };
  for (std::size_t s = 0; s < scans.size(); ++s) {
    acquisition::Scan& scan = scans[s];
    const auto membership = project.load_layer<std::uint32_t>(ids[s], store::layer::kMembership,
                                                              store::ElementType::kU32);
    for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
      if (!scan.valid[i] || (!keep.empty() && keep[s][i] == 0)) continue;
      std::uint32_t owner = membership ? (*membership)[i] : 0;
      if (owner == store::kDeletedPoints) {
        owner = 0;
        if (!settings.all_points) {
          ++result.deleted;
          leave_out(s, i);
          continue;
        }
      } else if (owner != 0) {
        const auto found = shown.find(owner);
        if (found == shown.end()) {
          owner = 0;  // a node no longer in the tree owns nothing
        } else if (!found->second && !settings.all_points) {
          ++result.hidden;
          leave_out(s, i);
          continue;
        }
      }
      if (!recolour || !scan.has_color()) continue;
      std::uint8_t* rgb = &scan.rgb[3 * i];
      const std::array<std::uint8_t, 3> out = colors.shown(ids[s], owner, {rgb[0], rgb[1], rgb[2]});
      std::copy(out.begin(), out.end(), rgb);
    }
  }
}

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

std::size_t count_points(const std::vector<acquisition::Scan>& scans,
                         const std::vector<std::vector<std::uint8_t>>& keep) {
  std::size_t points = 0;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const std::vector<std::uint8_t>& counted = keep.empty() ? scans[s].valid : keep[s];
    for (const std::uint8_t flag : counted) points += flag != 0 ? 1 : 0;
  }
  return points;
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

ExportResult export_project(const store::Project& project, const ExportSettings& settings) {
  // Masks, poses and channels from one state, whatever commits meanwhile.
  const store::Project::ReadSnapshot snapshot = project.read_snapshot();
  const std::vector<std::int64_t> ids = exported_ids(project, settings);
  std::vector<std::vector<std::uint8_t>> keep = keep_masks(project, settings, ids);
  std::vector<acquisition::Scan> scans;
  std::vector<std::optional<acquisition::ScanGeometry>> geometry;
  for (const std::int64_t id : ids) {
    scans.push_back(project.load_scan(id));
    geometry.push_back(store::load_geometry(project, id));
  }
  const std::vector<std::filesystem::path> outputs =
      settings.format == ExportFormat::kTriplet && scans.size() == 1
          ? acquisition::triplet_files(scans.front(), settings.output)
          : std::vector<std::filesystem::path>{settings.output};
  refuse_to_replace_inputs(project, outputs, settings.replace_existing);
  ExportResult result;
  result.scans = scans.size();
  show_as_the_model_does(project, ids, settings, scans, keep, result);
  std::vector<const acquisition::ScanGeometry*> geometry_of;
  for (const auto& g : geometry) geometry_of.push_back(g ? &*g : nullptr);
  std::vector<const std::vector<std::uint8_t>*> keep_of;
  for (const auto& mask : keep) keep_of.push_back(&mask);
  switch (settings.format) {
    case ExportFormat::kPtx:
      write_ptx(project, scans, settings);
      break;
    case ExportFormat::kPly:
      acquisition::write_ply(settings.output, scans, geometry_of, keep_of);
      break;
    case ExportFormat::kCsv:
      acquisition::write_csv(settings.output, scans, geometry_of, keep_of);
      break;
    case ExportFormat::kTriplet:
      write_triplet(project, scans, settings);
      break;
    case ExportFormat::kLas:
      acquisition::write_las(
          settings.output, scans, point_source_ids(project, ids), geometry_of, keep_of,
          las_wkt(common_coordinate_metadata(project, ids, project.scan_sources()), result));
      break;
    case ExportFormat::kE57:
      write_e57(project, ids, scans, keep_of, settings);
      break;
  }
  // The point formats leave mixed pixels out; the grid formats keep every
  // pixel, the valid ones (or with `merged` the kept ones) counted.
  const bool point_list = settings.format == ExportFormat::kPly ||
                          settings.format == ExportFormat::kCsv ||
                          settings.format == ExportFormat::kLas;
  result.points = point_list ? acquisition::count_exported_points(scans, geometry_of, keep_of)
                             : count_points(scans, keep);
  return result;
}

}  // namespace scanbench::modeling
