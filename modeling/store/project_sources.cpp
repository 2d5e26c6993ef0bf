// The scan_sources and scan_images tables: Project::put_scan_source,
// scan_sources, insert_image and images. Both are written by the import
// that made the scans, and live while it is done.
#include <sqlite3.h>

#include <nlohmann/json.hpp>

#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/row_checksum.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store {
namespace {

constexpr const char* kSelectSources = R"sql(
SELECT k.scan_id, k.details, k.checksum
FROM scan_sources k JOIN scans s ON s.id = k.scan_id
WHERE (SELECT state FROM commands WHERE id = s.created_by) = 'done'
ORDER BY k.scan_id)sql";

constexpr const char* kSelectImages = R"sql(
SELECT i.id, i.created_by, i.scan_id, i.description, i.format, i.data_crc, i.checksum, i.data
FROM scan_images i
WHERE (SELECT state FROM commands WHERE id = i.created_by) = 'done'
ORDER BY i.id)sql";

[[noreturn]] void damaged(const std::string& file, const std::string& what,
                          const std::string& problem) {
  core::FilePosition position;
  position.detail = what;
  throw core::InputError(file, position, "project is damaged: " + problem);
}

std::string to_json(const acquisition::ScanSource& source) {
  nlohmann::json json = {{"format", source.format},
                         {"guid", source.guid},
                         {"coordinate_metadata", source.coordinate_metadata},
                         {"points_in_file", source.points_in_file},
                         {"unplaced_points", source.unplaced_points},
                         {"round_trip_error_m", source.round_trip_error_m}};
  if (!source.files.empty()) {
    nlohmann::json& files = json["files"] = nlohmann::json::array();
    for (const acquisition::SourceFile& file : source.files)
      files.push_back({{"path", file.path}, {"device", file.device}, {"inode", file.inode}});
  }
  return json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

acquisition::ScanSource source_from_json(const std::string& text) {
  const nlohmann::json json = nlohmann::json::parse(text);
  acquisition::ScanSource source;
  source.format = json.at("format").get<std::string>();
  source.guid = json.at("guid").get<std::string>();
  source.coordinate_metadata = json.value("coordinate_metadata", "");
  source.points_in_file = json.at("points_in_file").get<std::uint64_t>();
  source.unplaced_points = json.at("unplaced_points").get<std::uint64_t>();
  source.round_trip_error_m = json.value("round_trip_error_m", 0.0);
  if (json.contains("files")) {  // imports since the source files were recorded
    for (const nlohmann::json& file : json["files"]) {
      source.files.push_back({file.at("path").get<std::string>(),
                              file.at("device").get<std::uint64_t>(),
                              file.at("inode").get<std::uint64_t>()});
    }
  }
  return source;
}

acquisition::ImageProjection projection_from_name(const std::string& name) {
  for (const auto projection :
       {acquisition::ImageProjection::kPinhole, acquisition::ImageProjection::kSpherical,
        acquisition::ImageProjection::kCylindrical,
        acquisition::ImageProjection::kVisualReference}) {
    if (name == acquisition::projection_name(projection)) return projection;
  }
  throw std::invalid_argument("unknown projection \"" + name + "\"");
}

// The image's description; `pose_key` names its pose: "T_scan_image" (tied
// to a scan) or "T_world_image".
std::string describe(const acquisition::ScanImage& image, const char* pose_key,
                     const Eigen::Isometry3d& pose) {
  return nlohmann::json{{"name", image.name},
                        {"guid", image.guid},
                        {"projection", acquisition::projection_name(image.projection)},
                        {"width", image.width},
                        {"height", image.height},
                        {"pixel_width", image.pixel_width},
                        {"pixel_height", image.pixel_height},
                        {"focal_length", image.focal_length},
                        {"principal_x", image.principal_x},
                        {"principal_y", image.principal_y},
                        {"radius", image.radius},
                        {pose_key, acquisition::row_major(pose)}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

acquisition::ScanImage image_from_json(const std::string& text, const std::string& format) {
  const nlohmann::json json = nlohmann::json::parse(text);
  acquisition::ScanImage image;
  image.name = json.at("name").get<std::string>();
  image.guid = json.at("guid").get<std::string>();
  image.projection = projection_from_name(json.at("projection").get<std::string>());
  image.width = json.at("width").get<int>();
  image.height = json.at("height").get<int>();
  image.pixel_width = json.at("pixel_width").get<double>();
  image.pixel_height = json.at("pixel_height").get<double>();
  image.focal_length = json.at("focal_length").get<double>();
  image.principal_x = json.at("principal_x").get<double>();
  image.principal_y = json.at("principal_y").get<double>();
  image.radius = json.at("radius").get<double>();
  // A tied image's pose is relative to its scan; the caller composes it.
  const char* key = json.contains("T_scan_image") ? "T_scan_image" : "T_world_image";
  const auto numbers = json.at(key).get<std::vector<double>>();
  if (numbers.size() != 16) {
    throw std::invalid_argument("a pose of " + std::to_string(numbers.size()) + " numbers");
  }
  std::array<double, 16> values;
  std::copy(numbers.begin(), numbers.end(), values.begin());
  image.T_world_image = Eigen::Isometry3d(acquisition::matrix_from_row_major(values));
  image.format = format;
  return image;
}

std::int64_t data_crc(std::span<const std::uint8_t> data) {
  return crc32_of(std::as_bytes(data));
}

}  // namespace

void Project::put_scan_source(Edit& edit, std::int64_t id, const acquisition::ScanSource& source) {
  check_edit(edit);
  stored_pixel_count(id, &edit);  // throws when there is no such scan
  const ScanSourceRecord record{id, to_json(source)};
  sqlite::Statement insert(
      db(), "INSERT INTO scan_sources (scan_id, details, checksum) VALUES (?1, ?2, ?3)",
      file_name());
  insert.bind_int(1, record.scan_id)
      .bind_text(2, record.details)
      .bind_int(3, checksum(record))
      .run();
}

std::map<std::int64_t, acquisition::ScanSource> Project::scan_sources() const {
  std::map<std::int64_t, acquisition::ScanSource> out;
  for (sqlite::Statement select(db(), kSelectSources, file_name()); select.step();) {
    const ScanSourceRecord record{select.column_int(0), select.column_text(1)};
    const std::string what = "source of scan " + std::to_string(record.scan_id);
    if (checksum(record) != select.column_int(2)) {
      damaged(file_name(), what, "the row fails its checksum (changed outside scanbench?)");
    }
    try {
      out[record.scan_id] = source_from_json(record.details);
    } catch (const std::exception& e) {
      damaged(file_name(), what, e.what());
    }
  }
  return out;
}

std::int64_t Project::insert_image(Edit& edit, std::optional<std::int64_t> scan_id,
                                   const Eigen::Isometry3d& T_world_scan,
                                   const acquisition::ScanImage& image) {
  check_edit(edit);
  if (scan_id) stored_pixel_count(*scan_id, &edit);  // throws when there is no such scan
  if (image.format != "jpeg" && image.format != "png") {
    throw core::InputError(file_name(), {{}, {}, "image \"" + image.name + "\""},
                           "is " + image.format + "; images are JPEG or PNG");
  }
  const std::string description =
      scan_id ? describe(image, "T_scan_image", T_world_scan.inverse() * image.T_world_image)
              : describe(image, "T_world_image", image.T_world_image);
  ImageRecord record{edit.command_id(), scan_id, description, image.format, data_crc(image.data)};
  sqlite::Statement insert(db(),
                           "INSERT INTO scan_images (created_by, scan_id, description, format, "
                           "data, data_crc, checksum) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
                           file_name());
  insert.bind_int(1, record.created_by);
  if (scan_id) {
    insert.bind_int(2, *scan_id);
  } else {
    insert.bind_null(2);
  }
  insert.bind_text(3, record.description).bind_text(4, record.format).bind_blob(5, image.data);
  insert.bind_int(6, record.data_crc).bind_int(7, checksum(record)).run();
  return sqlite3_last_insert_rowid(db());
}

std::vector<StoredImage> Project::images(bool with_data) const {
  std::map<std::int64_t, Eigen::Isometry3d> poses;  // of the live scans, now
  for (const StoredScanSummary& stored : scans()) poses[stored.id] = stored.summary.T_world_scan;
  std::vector<StoredImage> out;
  for (sqlite::Statement select(db(), kSelectImages, file_name()); select.step();) {
    StoredImage stored;
    stored.id = select.column_int(0);
    ImageRecord record;
    record.created_by = select.column_int(1);
    if (!select.is_null(2)) record.scan_id = select.column_int(2);
    record.description = select.column_text(3);
    record.format = select.column_text(4);
    record.data_crc = select.column_int(5);
    const std::string what = "image " + std::to_string(stored.id);
    if (checksum(record) != select.column_int(6)) {
      damaged(file_name(), what, "the row fails its checksum (changed outside scanbench?)");
    }
    try {
      stored.image = image_from_json(record.description, record.format);
    } catch (const std::exception& e) {
      damaged(file_name(), what, e.what());
    }
    stored.scan_id = record.scan_id;
    if (stored.scan_id) {
      const auto pose = poses.find(*stored.scan_id);
      if (pose == poses.end()) continue;  // its scan is gone with an undone import
      stored.image.T_world_image = pose->second * stored.image.T_world_image;
    }
    if (with_data) {
      const std::span<const std::uint8_t> data = select.column_blob(7);
      if (data_crc(data) != record.data_crc) damaged(file_name(), what, "its data fails its CRC");
      stored.image.data.assign(data.begin(), data.end());
    }
    out.push_back(std::move(stored));
  }
  return out;
}

}  // namespace scanbench::store
