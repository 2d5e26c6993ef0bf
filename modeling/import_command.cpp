#include "modeling/import_command.hpp"

#include <chrono>
#include <nlohmann/json.hpp>
#include <set>

#include "core/errors.hpp"
#include "core/memory.hpp"
#include "core/timing.hpp"
#include "modeling/command_json.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {

// The blobs the check keeps until they are stored, parked in a
// core::SpillFile. Best effort: where the file cannot take them (none can
// be made, a full disk), the blobs stay in memory as the check kept them
// before.
class LayerSpill {
 public:
  // Moves every layer's blob of `scan` to the file and says where each went
  // in `places`; false (the blobs left in `scan`) when the file cannot take
  // them.
  bool put(store::EncodedScan& scan, std::vector<CheckedImport::Scan::Place>& places) {
    std::vector<CheckedImport::Scan::Place> written;
    for (const store::EncodedLayer& layer : scan.layers) {
      const std::optional<core::SpillFile::Extent> extent =
          file_.put(layer.blob.data(), layer.blob.size());
      if (!extent) {
        for (const CheckedImport::Scan::Place& place : written) file_.release(place);
        return false;
      }
      written.push_back(*extent);
    }
    for (store::EncodedLayer& layer : scan.layers) {
      layer.blob.clear();
      layer.blob.shrink_to_fit();
    }
    places = std::move(written);
    return true;
  }

  // `scan` with its layers' blobs read back.
  store::EncodedScan get(const store::EncodedScan& scan,
                         const std::vector<CheckedImport::Scan::Place>& places) const {
    store::EncodedScan whole = scan;
    for (std::size_t k = 0; k < whole.layers.size(); ++k) {
      std::vector<std::uint8_t>& blob = whole.layers[k].blob;
      blob.resize(places[k].bytes);
      file_.get(places[k], blob.data());
    }
    return whole;
  }

 private:
  core::SpillFile file_;
};

namespace {

constexpr const char* kStage = "import";

// The settings and the files they read.
std::string settings_json(std::span<const std::filesystem::path> files,
                          const ImportSettings& settings) {
  nlohmann::json document = nlohmann::json::parse(settings_to_json(settings));
  document["files"] = nlohmann::json::array();
  for (const std::filesystem::path& file : files) document["files"].push_back(file.string());
  return dump(document);
}

// A scan that is already in the project, or earlier in this import.
[[noreturn]] void refuse_duplicate(const std::filesystem::path& file, const std::string& scan,
                                   std::optional<std::int64_t> twin) {
  core::FilePosition position;
  position.detail = "scan \"" + scan + "\"";
  throw core::InputError(
      file.string(), position,
      (twin ? "is already in the project as scan " + std::to_string(*twin)
            : std::string("appears twice in this import")) +
          "; importing it again would add a twin (--allow-duplicate imports it anyway)");
}

// The scan with what its file recorded of its geometry, ready to store.
store::EncodedScan encode_imported(const acquisition::ImportedScan& imported) {
  store::EncodedScan encoded = store::encode_scan(imported.scan);
  for (store::EncodedLayer& layer : store::encode_recorded_geometry(imported.recorded))
    encoded.layers.push_back(std::move(layer));
  return encoded;
}

// What the check may keep in memory [bytes] (images, and the channels the
// temporary file could not take): a quarter of what is available, 1 GiB
// where that cannot be told.
std::uint64_t keep_budget_bytes() {
  return core::available_memory_bytes().value_or(std::uint64_t{4} << 30) / 4;
}

std::uint64_t encoded_bytes(const store::EncodedScan& scan) {
  std::uint64_t bytes = 0;
  for (const store::EncodedLayer& layer : scan.layers) bytes += layer.blob.size();
  return bytes;
}

std::uint64_t image_bytes(const std::vector<acquisition::ScanImage>& images) {
  std::uint64_t bytes = 0;
  for (const acquisition::ScanImage& image : images) bytes += image.data.size();
  return bytes;
}

// Drops what a file's check kept (it is read again when stored) and
// returns the bytes it held.
std::uint64_t release(CheckedImport::File& file) {
  std::uint64_t bytes = image_bytes(file.loose_images);
  for (CheckedImport::Scan& scan : file.scans) {
    bytes += image_bytes(scan.images);
    if (scan.encoded) bytes += encoded_bytes(*scan.encoded);  // 0 when spilled
    scan.encoded.reset();
    scan.spilled.clear();
    scan.images.clear();
  }
  file.loose_images.clear();
  file.kept = false;
  return bytes;
}

// `file` now also keeps `bytes` more: taken from `budget`, or, when they do
// not fit, everything the file keeps is released (and its bytes given
// back).
void keep_within(CheckedImport::File& file, std::uint64_t bytes, std::uint64_t& budget) {
  if (bytes <= budget) {
    budget -= bytes;
  } else {
    budget += release(file) - bytes;  // what the file held before these bytes
  }
}

// Writes one scan, with its source and images, as a part of `command`.
std::int64_t store_scan(store::Project& project, store::Project::LongCommand& command,
                        const store::EncodedScan& scan, const acquisition::ScanSource& source,
                        const std::vector<acquisition::ScanImage>& images) {
  store::Project::Edit part = command.part();
  const std::int64_t id = project.insert_scan(part, scan);
  project.put_scan_source(part, id, source);
  for (const acquisition::ScanImage& image : images)
    project.insert_image(part, id, scan.metadata.T_world_scan, image);
  part.commit_part();
  return id;
}

void store_loose_image(store::Project& project, store::Project::LongCommand& command,
                       const acquisition::ScanImage& image) {
  store::Project::Edit part = command.part();
  project.insert_image(part, std::nullopt, Eigen::Isometry3d::Identity(), image);
  part.commit_part();
}

// Stores a file the check did not keep: read again, each scan matched to
// what the check found.
void store_read_again(store::Project& project, store::Project::LongCommand& command,
                      const CheckedImport::File& file, const ImportSettings& settings,
                      ImportResult& result) {
  std::size_t next = 0;
  const auto on_scan = [&](acquisition::ImportedScan&& imported) {
    const store::EncodedScan encoded = encode_imported(imported);
    if (next >= file.scans.size() || file.scans[next].digest != encoded.content_digest) {
      throw core::InputError(file.path.string(), {},
                             "the file changed while it was imported; nothing was stored");
    }
    imported.source.files = file.scans[next].source.files;
    ++next;
    result.scan_ids.push_back(
        store_scan(project, command, encoded, imported.source, imported.images));
    result.images += imported.images.size();
  };
  const auto on_loose_image = [&](acquisition::ScanImage&& image) {
    store_loose_image(project, command, image);
    ++result.images;
  };
  acquisition::read_scan_file(file.path, settings.readers, on_scan, on_loose_image);
  if (next != file.scans.size()) {
    throw core::InputError(file.path.string(), {},
                           "the file changed while it was imported; nothing was stored");
  }
}

}  // namespace

CheckedImport check_scan_files(std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress) {
  CheckedImport checked;
  checked.spill = std::make_shared<LayerSpill>();
  std::uint64_t budget = keep_budget_bytes();
  std::set<std::int64_t> digests;  // of the scans of this import
  for (std::size_t f = 0; f < files.size(); ++f) {
    progress.throw_if_cancelled(kStage);
    CheckedImport::File& file = checked.files.emplace_back();
    file.path = files[f];
    file.kept = true;
    const auto on_scan = [&](acquisition::ImportedScan&& imported) {
      CheckedImport::Scan& scan = file.scans.emplace_back();
      scan.name = imported.scan.name;
      scan.digest = store::scan_content_digest(imported.scan);
      if (!settings.allow_duplicates && !digests.insert(scan.digest).second)
        refuse_duplicate(file.path, imported.scan.name, std::nullopt);
      scan.source = std::move(imported.source);
      acquisition::identify_source_files(file.path, scan.source);
      if (!file.kept) return;
      scan.encoded = encode_imported(imported);
      scan.images = std::move(imported.images);
      std::uint64_t held = image_bytes(scan.images);
      if (!checked.spill->put(*scan.encoded, scan.spilled)) held += encoded_bytes(*scan.encoded);
      keep_within(file, held, budget);
    };
    const auto on_loose_image = [&](acquisition::ScanImage&& image) {
      if (!file.kept) return;
      const std::uint64_t bytes = image.data.size();
      file.loose_images.push_back(std::move(image));
      keep_within(file, bytes, budget);
    };
    acquisition::read_scan_file(file.path, settings.readers, on_scan, on_loose_image);
    progress.update({kStage, f + 1, 2 * files.size(), file.path.filename().string()});
  }
  return checked;
}

ImportResult store_checked_scans(store::Project& project, const CheckedImport& checked,
                                 const ImportSettings& settings, core::Progress& progress) {
  std::vector<std::filesystem::path> paths;
  for (const CheckedImport::File& file : checked.files) {
    paths.push_back(file.path);
    for (const CheckedImport::Scan& scan : file.scans) {
      const auto twin = project.scan_with_content(scan.digest);
      if (twin && !settings.allow_duplicates) refuse_duplicate(file.path, scan.name, twin);
    }
  }
  progress.throw_if_cancelled(kStage);
  ImportResult result;
  // One part per scan: a file of many large scans never sits in memory
  // whole, and the write lock is held only while a scan's rows are written
  // (compression, most of the work, happens before).
  store::Project::LongCommand command =
      project.begin_long_command(kStage, settings_json(paths, settings));
  result.command_id = command.command_id();
  for (std::size_t f = 0; f < checked.files.size(); ++f) {
    progress.throw_if_cancelled(kStage);
    const CheckedImport::File& file = checked.files[f];
    if (file.kept) {
      for (const CheckedImport::Scan& scan : file.scans) {
        std::optional<store::EncodedScan> read_back;
        if (!scan.spilled.empty()) read_back = checked.spill->get(*scan.encoded, scan.spilled);
        result.scan_ids.push_back(store_scan(
            project, command, read_back ? *read_back : *scan.encoded, scan.source, scan.images));
        result.images += scan.images.size();
      }
      for (const acquisition::ScanImage& image : file.loose_images)
        store_loose_image(project, command, image);
      result.images += file.loose_images.size();
    } else {
      store_read_again(project, command, file, settings, result);
    }
    for (const CheckedImport::Scan& scan : file.scans) {
      result.unplaced_points += scan.source.unplaced_points;
      if (scan.source.round_trip_error_m > acquisition::kPromisedRoundTripM)
        result.beyond_promise.push_back({file.path, scan.name, scan.source.round_trip_error_m});
    }
    progress.update({kStage, checked.files.size() + f + 1, 2 * checked.files.size(),
                     file.path.filename().string()});
  }
  progress.throw_if_cancelled(kStage);
  // New scans can sample the merged surfaces more finely: the earlier
  // merge's keep masks no longer hold.
  store::Project::Edit finish = command.finish();
  for (const store::StoredScanSummary& stored : project.scans()) {
    project.remove_layer(finish, stored.id, store::layer::kKeep);
  }
  finish.commit(result_json(result));
  return result;
}

ImportResult import_scans(store::Project& project, std::span<const std::filesystem::path> files,
                          const ImportSettings& settings, core::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const CheckedImport checked = check_scan_files(files, settings, progress);
  ImportResult result = store_checked_scans(project, checked, settings, progress);
  result.seconds = core::seconds_since(start);
  return result;
}

ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  // Bad input is bad input whatever the project: checked before it is opened.
  const CheckedImport checked = check_scan_files(files, settings, progress);
  const auto store = [&](store::Project& project) {
    ImportResult result = store_checked_scans(project, checked, settings, progress);
    result.seconds = core::seconds_since(start);
    return result;
  };
  std::error_code error;
  if (!std::filesystem::exists(std::filesystem::symlink_status(project_path, error))) {
    // A new project is filled as a draft and appears only once the import is
    // done: a refused import leaves nothing, and no other process ever sees
    // it half made.
    store::Project::Draft draft = store::Project::create_draft(project_path);
    ImportResult result = store(draft.project());
    if (draft.publish()) {
      result.created_project = true;
      return result;
    }
    // Another process created the project meanwhile: import into that one.
  }
  store::Project project = store::Project::open(project_path);
  return store(project);
}

}  // namespace scanbench::modeling
