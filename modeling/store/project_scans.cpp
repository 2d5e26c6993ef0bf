// The scans and scan_poses tables: encode_scan, Project::insert_scan,
// set_pose, scans, load_scan. Every record is checksummed when written and
// verified when read (checksummed_rows.hpp).
#include <sqlite3.h>

#include <array>
#include <bit>
#include <cassert>
#include <climits>
#include <cstring>

#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/row_checksum.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store {

namespace {

static_assert(std::endian::native == std::endian::little,
              "poses are stored as little-endian doubles");

constexpr int kFirstScanColumn = 1;  // after s.id
constexpr int kFirstPoseColumn = kFirstScanColumn + kScanRecordColumnCount;

// Every live scan (its import done) with its current pose: the pose row of
// the newest done command, in journal order.
const std::string kSelectScans =
    sql_of({"SELECT s.id, ", kScanRecordColumns, ", ", kPoseRecordColumns, R"sql(
FROM scans s JOIN scan_poses p ON p.scan_id = s.id
WHERE (SELECT state FROM commands WHERE id = s.created_by) = 'done'
  AND p.command_id = (SELECT q.command_id FROM scan_poses q JOIN commands c ON c.id = q.command_id
                      WHERE q.scan_id = s.id AND c.state = 'done'
                      ORDER BY c.seq DESC LIMIT 1))sql"});

constexpr const char* kInsertScan = R"sql(
INSERT INTO scans (created_by, name, rows, columns, angle_model, azimuth_start_rad,
                   azimuth_step_rad, elevation_start_rad, elevation_step_rad, scanner_name,
                   source_file, valid_points, has_color, has_intensity, content_digest, checksum,
                   layout)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17))sql";

constexpr const char* kInsertPose = R"sql(
INSERT OR REPLACE INTO scan_poses (scan_id, command_id, T_world_scan, scanner_x, scanner_y,
                                   scanner_z, bbox_min_x, bbox_min_y, bbox_min_z, bbox_max_x,
                                   bbox_max_y, bbox_max_z, checksum)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13))sql";

constexpr std::size_t kPoseBytes = 16 * sizeof(double);

[[noreturn]] void damaged(const std::string& file, std::int64_t id, const std::string& problem) {
  core::FilePosition position;
  position.detail = "scan " + std::to_string(id);
  throw core::InputError(file, position, "project is damaged: " + problem);
}

// Row-major 4x4, raw doubles: bit-exact, including -0.0.
std::vector<std::uint8_t> encode_pose(const Eigen::Isometry3d& pose) {
  const std::array<double, 16> values = acquisition::row_major(pose);
  std::vector<std::uint8_t> bytes(kPoseBytes);
  std::memcpy(bytes.data(), values.data(), kPoseBytes);
  return bytes;
}

Eigen::Isometry3d decode_pose(std::span<const std::uint8_t> bytes, const std::string& file,
                              std::int64_t id) {
  if (bytes.size() != kPoseBytes) damaged(file, id, "pose is not 16 doubles");
  std::array<double, 16> values{};
  std::memcpy(values.data(), bytes.data(), kPoseBytes);
  Eigen::Isometry3d pose;
  pose.matrix() = acquisition::matrix_from_row_major(values);
  return pose;
}

ScanRecord scan_record(std::int64_t command_id, const EncodedScan& encoded) {
  const acquisition::Scan& scan = encoded.metadata;
  ScanRecord r;
  r.created_by = command_id;
  r.name = scan.name;
  r.rows = scan.rows;
  r.columns = scan.columns;
  r.angle_model = acquisition::angle_model_name(scan.is_spherical());
  if (const auto* a = std::get_if<acquisition::SphericalAngles>(&scan.angles)) {
    r.angles = {a->azimuth_start_rad, a->azimuth_step_rad, a->elevation_start_rad,
                a->elevation_step_rad};
  }
  r.scanner_name = scan.scanner.name;
  r.source_file = scan.scanner.source_file;
  r.valid_points = static_cast<std::int64_t>(encoded.summary.valid_points);
  r.has_color = encoded.summary.has_color;
  r.has_intensity = encoded.summary.has_intensity;
  r.content_digest = encoded.content_digest;
  r.layout = scan.is_scattered() ? "scattered" : "grid";
  return r;
}

void bind_scan_record(sqlite::Statement& insert, const ScanRecord& r) {
  insert.bind_int(1, r.created_by).bind_text(2, r.name).bind_int(3, r.rows).bind_int(4, r.columns);
  insert.bind_text(5, r.angle_model);
  for (int k = 0; k < 4; ++k)
    insert.bind_optional_double(6 + k, r.angles[static_cast<std::size_t>(k)]);
  insert.bind_text(10, r.scanner_name).bind_text(11, r.source_file);
  insert.bind_int(12, r.valid_points).bind_int(13, r.has_color).bind_int(14, r.has_intensity);
  insert.bind_int(15, r.content_digest).bind_int(16, checksum(r)).bind_text(17, r.layout);
}

void insert_pose(sqlite3* db, const std::string& file, std::int64_t id, std::int64_t command_id,
                 const Eigen::Isometry3d& T_world_scan, const Eigen::Vector3d& scanner_world,
                 const std::optional<Eigen::AlignedBox3d>& box) {
  PoseRecord r;
  r.scan_id = id;
  r.command_id = command_id;
  r.pose = encode_pose(T_world_scan);
  r.scanner = {scanner_world.x(), scanner_world.y(), scanner_world.z()};
  for (int axis = 0; axis < 3; ++axis) {
    r.bbox[static_cast<std::size_t>(axis)] = box ? std::optional(box->min()[axis]) : std::nullopt;
    r.bbox[static_cast<std::size_t>(3 + axis)] =
        box ? std::optional(box->max()[axis]) : std::nullopt;
  }
  sqlite::Statement insert(db, kInsertPose, file);
  insert.bind_int(1, r.scan_id).bind_int(2, r.command_id).bind_blob(3, r.pose);
  for (int k = 0; k < 3; ++k) insert.bind_double(4 + k, r.scanner[static_cast<std::size_t>(k)]);
  for (int k = 0; k < 6; ++k)
    insert.bind_optional_double(7 + k, r.bbox[static_cast<std::size_t>(k)]);
  insert.bind_int(13, checksum(r)).run();
}

int dimension(std::int64_t value, const std::string& file, std::int64_t id) {
  if (value < 0 || value > INT_MAX) damaged(file, id, "impossible grid size");
  return static_cast<int>(value);
}

// The scan and pose records of a kSelectScans row, verified.
std::pair<ScanRecord, PoseRecord> verified_records(const sqlite::Statement& row,
                                                   const std::string& file, std::int64_t id) {
  auto [scan, scan_sum] = read_scan_record(row, kFirstScanColumn);
  if (checksum(scan) != scan_sum) {
    damaged(file, id, "the scan's record fails its checksum (changed outside scanbench?)");
  }
  auto [pose, pose_sum] = read_pose_record(row, kFirstPoseColumn);
  if (checksum(pose) != pose_sum) {
    damaged(file, id, "the scan's pose fails its checksum (changed outside scanbench?)");
  }
  return {std::move(scan), std::move(pose)};
}

StoredScanSummary read_summary(const sqlite::Statement& row, const std::string& file) {
  StoredScanSummary stored;
  stored.id = row.column_int(0);
  const auto [scan, pose] = verified_records(row, file, stored.id);
  auto& summary = stored.summary;
  summary.name = scan.name;
  summary.rows = dimension(scan.rows, file, stored.id);
  summary.columns = dimension(scan.columns, file, stored.id);
  if (scan.angle_model != "spherical" && scan.angle_model != "per_pixel") {
    damaged(file, stored.id, "unknown angle model");
  }
  summary.spherical = scan.angle_model == "spherical";
  if (scan.layout != "grid" && (scan.layout != "scattered" || summary.spherical)) {
    damaged(file, stored.id, "unknown layout");
  }
  summary.scattered = scan.layout == "scattered";
  summary.T_world_scan = decode_pose(pose.pose, file, stored.id);
  summary.scanner.name = scan.scanner_name;
  summary.scanner.source_file = scan.source_file;
  summary.scanner.position_world = {pose.scanner[0], pose.scanner[1], pose.scanner[2]};
  summary.valid_points = static_cast<std::size_t>(scan.valid_points);
  summary.has_color = scan.has_color != 0;
  summary.has_intensity = scan.has_intensity != 0;
  if (pose.bbox[0]) {
    summary.bbox_world =
        Eigen::AlignedBox3d(Eigen::Vector3d(*pose.bbox[0], *pose.bbox[1], *pose.bbox[2]),
                            Eigen::Vector3d(*pose.bbox[3], *pose.bbox[4], *pose.bbox[5]));
  }
  return stored;
}

acquisition::AngleModel read_angles(const sqlite::Statement& row,
                                    const acquisition::ScanSummary& summary) {
  if (!summary.spherical) return acquisition::PerPixelDirections{{}, summary.scattered};
  const ScanRecord scan = read_scan_record(row, kFirstScanColumn).first;
  return acquisition::SphericalAngles{*scan.angles[0], *scan.angles[1], *scan.angles[2],
                                      *scan.angles[3]};
}

// Loads a channel layer that must be there.
template <typename T>
std::vector<T> required_layer(const Project& project, std::int64_t id, const char* name,
                              ElementType type) {
  std::optional<std::vector<T>> values = project.load_layer<T>(id, name, type);
  if (!values) damaged(project.path().string(), id, std::string("layer ") + name + " is missing");
  return std::move(*values);
}

}  // namespace

std::int64_t scan_content_digest(const acquisition::Scan& scan) {
  return content_digest(scan.rows, scan.columns, acquisition::angle_model_name(scan.is_spherical()),
                        std::as_bytes(std::span(scan.range_m)),
                        std::as_bytes(std::span(scan.valid)));
}

EncodedScan encode_scan(const acquisition::Scan& scan) {
  assert(acquisition::check_consistency(scan).empty() &&
         "only a consistent scan is stored (see acquisition::check_consistency)");
  EncodedScan encoded;
  encoded.summary = acquisition::summarize(scan);
  encoded.metadata.name = scan.name;
  encoded.metadata.rows = scan.rows;
  encoded.metadata.columns = scan.columns;
  encoded.metadata.T_world_scan = scan.T_world_scan;
  encoded.metadata.scanner = scan.scanner;
  auto& layers = encoded.layers;
  layers.push_back(encode_layer<float>(layer::kRange, ElementType::kF32, scan.range_m));
  layers.push_back(encode_layer<std::uint8_t>(layer::kValid, ElementType::kU8, scan.valid));
  encoded.content_digest = scan_content_digest(scan);
  if (scan.has_intensity()) {
    layers.push_back(encode_layer<float>(layer::kIntensity, ElementType::kF32, scan.intensity));
  }
  if (scan.has_color()) {
    layers.push_back(encode_layer<std::uint8_t>(layer::kRgb, ElementType::kU8x3, scan.rgb));
  }
  if (const auto* per_pixel = std::get_if<acquisition::PerPixelDirections>(&scan.angles)) {
    layers.push_back(encode_layer<Eigen::Vector3f>(layer::kDirections, ElementType::kF32x3,
                                                   per_pixel->directions));
    encoded.metadata.angles = acquisition::PerPixelDirections{{}, per_pixel->scattered};
  } else {
    encoded.metadata.angles = scan.angles;
  }
  return encoded;
}

std::size_t Project::stored_pixel_count(std::int64_t id, const Edit* edit) const {
  sqlite::Statement statement(db(), R"sql(
SELECT rows * columns FROM scans
WHERE id = ?1 AND (created_by = ?2 OR
                   (SELECT state FROM commands WHERE id = scans.created_by) = 'done'))sql",
                              file_name());
  statement.bind_int(1, id).bind_int(2, edit != nullptr ? edit->command_id() : -1);
  if (!statement.step()) {
    throw core::InputError(file_name(), {}, "no scan with id " + std::to_string(id));
  }
  return static_cast<std::size_t>(statement.column_int(0));
}

std::int64_t Project::insert_scan(Edit& edit, const EncodedScan& scan) {
  check_edit(edit);
  sqlite::Statement insert(db(), kInsertScan, file_name());
  bind_scan_record(insert, scan_record(edit.command_id(), scan));
  insert.run();
  const std::int64_t id = sqlite3_last_insert_rowid(db());
  insert_pose(db(), file_name(), id, edit.command_id(), scan.metadata.T_world_scan,
              scan.metadata.scanner.position_world, scan.summary.bbox_world);
  for (const EncodedLayer& layer : scan.layers) put_layer(edit, id, layer);
  return id;
}

void Project::set_pose(Edit& edit, std::int64_t id, const acquisition::Scan& scan) {
  check_edit(edit);
  [[maybe_unused]] const std::size_t n = stored_pixel_count(id, &edit);  // throws when none
  assert(n == scan.pixel_count() && "set_pose takes the stored scan");
  set_pose(edit, id, scan.T_world_scan, acquisition::world_bounds(scan));
}

void Project::set_pose(Edit& edit, std::int64_t id, const Eigen::Isometry3d& T_world_scan,
                       const std::optional<Eigen::AlignedBox3d>& bbox_world) {
  check_edit(edit);
  assert(T_world_scan.matrix().allFinite() && "set_pose takes a finite pose");
  // The scanner moves with its scan: its position in the scan frame stays.
  const StoredScanSummary before = current_summary(id);  // throws when there is none
  const Eigen::Vector3d scanner_world =
      T_world_scan * before.summary.T_world_scan.inverse() * before.summary.scanner.position_world;
  insert_pose(db(), file_name(), id, edit.command_id(), T_world_scan, scanner_world, bbox_world);
}

StoredScanSummary Project::current_summary(std::int64_t id) const {
  const std::string sql = kSelectScans + " AND s.id = ?1";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  select.bind_int(1, id);
  if (!select.step()) {
    throw core::InputError(file_name(), {}, "no scan with id " + std::to_string(id));
  }
  return read_summary(select, file_name());
}

std::vector<StoredScanSummary> Project::scans() const {
  const std::string sql = kSelectScans + " ORDER BY s.id";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  std::vector<StoredScanSummary> result;
  while (select.step()) result.push_back(read_summary(select, file_name()));
  return result;
}

std::optional<std::int64_t> Project::scan_with_content(std::int64_t digest) const {
  sqlite::Statement select(db(), R"sql(
SELECT id FROM scans
WHERE content_digest = ?1 AND (SELECT state FROM commands WHERE id = scans.created_by) = 'done'
ORDER BY id LIMIT 1)sql",
                           file_name());
  select.bind_int(1, digest);
  if (!select.step()) return std::nullopt;
  return select.column_int(0);
}

acquisition::Scan Project::load_scan_description(std::int64_t id) const {
  const std::string sql = kSelectScans + " AND s.id = ?1";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  select.bind_int(1, id);
  if (!select.step()) {
    throw core::InputError(file_name(), {}, "no scan with id " + std::to_string(id));
  }
  const acquisition::ScanSummary summary = read_summary(select, file_name()).summary;
  acquisition::Scan scan;
  scan.name = summary.name;
  scan.rows = summary.rows;
  scan.columns = summary.columns;
  scan.angles = read_angles(select, summary);
  scan.T_world_scan = summary.T_world_scan;
  scan.scanner = summary.scanner;
  return scan;
}

acquisition::Scan Project::load_scan(std::int64_t id, ScanChannels channels) const {
  acquisition::Scan scan = load_scan_description(id);
  const acquisition::ScanSummary summary = current_summary(id).summary;
  scan.range_m = required_layer<float>(*this, id, layer::kRange, ElementType::kF32);
  scan.valid = required_layer<std::uint8_t>(*this, id, layer::kValid, ElementType::kU8);
  if (summary.has_intensity && channels.intensity) {
    scan.intensity = required_layer<float>(*this, id, layer::kIntensity, ElementType::kF32);
  }
  if (summary.has_color && channels.color) {
    scan.rgb = required_layer<std::uint8_t>(*this, id, layer::kRgb, ElementType::kU8x3);
  }
  if (!summary.spherical) {
    std::get<acquisition::PerPixelDirections>(scan.angles).directions =
        required_layer<Eigen::Vector3f>(*this, id, layer::kDirections, ElementType::kF32x3);
  }
  return scan;
}

}  // namespace scanbench::store
