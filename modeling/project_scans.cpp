// The scans and scan_poses tables: encode_scan, Project::insert_scan,
// set_pose, scans, load_scan.
#include <sqlite3.h>

#include <array>
#include <bit>
#include <cassert>
#include <climits>
#include <cstring>

#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"
#include "modeling/project.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {

namespace {

static_assert(std::endian::native == std::endian::little,
              "poses are stored as little-endian doubles");

// Column order of kSelectScans.
enum Column : int {
  kId = 0,
  kName,
  kRows,
  kColumns,
  kAngleModel,
  kAzimuthStart,
  kAzimuthStep,
  kElevationStart,
  kElevationStep,
  kScannerName,
  kSourceFile,
  kValidPoints,
  kHasColor,
  kHasIntensity,
  kPose,
  kScannerX,
  kScannerY,
  kScannerZ,
  kBboxMinX,
  kBboxMinY,
  kBboxMinZ,
  kBboxMaxX,
  kBboxMaxY,
  kBboxMaxZ,
};

// Every live scan (its import done) with its current pose: the pose row of
// the newest done command, in journal order.
constexpr const char* kSelectScans = R"sql(
SELECT s.id, s.name, s.rows, s.columns, s.angle_model,
       s.azimuth_start_rad, s.azimuth_step_rad, s.elevation_start_rad, s.elevation_step_rad,
       s.scanner_name, s.source_file, s.valid_points, s.has_color, s.has_intensity,
       p.T_world_scan, p.scanner_x, p.scanner_y, p.scanner_z,
       p.bbox_min_x, p.bbox_min_y, p.bbox_min_z, p.bbox_max_x, p.bbox_max_y, p.bbox_max_z
FROM scans s JOIN scan_poses p ON p.scan_id = s.id
WHERE s.created_by IN (SELECT id FROM commands WHERE state = 'done')
  AND p.command_id = (SELECT q.command_id FROM scan_poses q JOIN commands c ON c.id = q.command_id
                      WHERE q.scan_id = s.id AND c.state = 'done'
                      ORDER BY c.seq DESC LIMIT 1))sql";

constexpr const char* kInsertScan = R"sql(
INSERT INTO scans (created_by, name, rows, columns, angle_model, azimuth_start_rad,
                   azimuth_step_rad, elevation_start_rad, elevation_step_rad, scanner_name,
                   source_file, valid_points, has_color, has_intensity)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14))sql";

constexpr const char* kInsertPose = R"sql(
INSERT OR REPLACE INTO scan_poses (scan_id, command_id, T_world_scan, scanner_x, scanner_y,
                                   scanner_z, bbox_min_x, bbox_min_y, bbox_min_z, bbox_max_x,
                                   bbox_max_y, bbox_max_z)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12))sql";

constexpr std::size_t kPoseBytes = 16 * sizeof(double);

[[noreturn]] void damaged(const std::string& file, std::int64_t id, const std::string& problem) {
  core::FilePosition position;
  position.detail = "scan " + std::to_string(id);
  throw core::InputError(file, position, "project is damaged: " + problem);
}

// Row-major 4x4, raw doubles: bit-exact, including -0.0.
std::array<std::uint8_t, kPoseBytes> encode_pose(const Eigen::Isometry3d& pose) {
  const std::array<double, 16> values = acquisition::row_major(pose);
  std::array<std::uint8_t, kPoseBytes> bytes{};
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

void bind_scan_row(sqlite::Statement& insert, std::int64_t command_id, const EncodedScan& encoded) {
  const acquisition::Scan& scan = encoded.metadata;
  const acquisition::ScanSummary& summary = encoded.summary;
  insert.bind_int(1, command_id).bind_text(2, scan.name);
  insert.bind_int(3, scan.rows).bind_int(4, scan.columns);
  insert.bind_text(5, acquisition::angle_model_name(scan.is_spherical()));
  const auto* angles = std::get_if<acquisition::SphericalAngles>(&scan.angles);
  const auto angle = [&](double acquisition::SphericalAngles::*field) {
    return angles != nullptr ? std::optional<double>(angles->*field) : std::nullopt;
  };
  insert.bind_optional_double(6, angle(&acquisition::SphericalAngles::azimuth_start_rad))
      .bind_optional_double(7, angle(&acquisition::SphericalAngles::azimuth_step_rad))
      .bind_optional_double(8, angle(&acquisition::SphericalAngles::elevation_start_rad))
      .bind_optional_double(9, angle(&acquisition::SphericalAngles::elevation_step_rad));
  insert.bind_text(10, scan.scanner.name).bind_text(11, scan.scanner.source_file);
  insert.bind_int(12, static_cast<std::int64_t>(summary.valid_points))
      .bind_int(13, summary.has_color)
      .bind_int(14, summary.has_intensity);
}

void insert_pose(sqlite3* db, const std::string& file, std::int64_t id, std::int64_t command_id,
                 const Eigen::Isometry3d& T_world_scan, const Eigen::Vector3d& scanner_world,
                 const std::optional<Eigen::AlignedBox3d>& box) {
  const auto pose_bytes = encode_pose(T_world_scan);
  sqlite::Statement insert(db, kInsertPose, file);
  insert.bind_int(1, id).bind_int(2, command_id).bind_blob(3, pose_bytes);
  for (int axis = 0; axis < 3; ++axis) insert.bind_double(4 + axis, scanner_world[axis]);
  for (int axis = 0; axis < 3; ++axis) {
    insert.bind_optional_double(7 + axis, box ? std::optional(box->min()[axis]) : std::nullopt)
        .bind_optional_double(10 + axis, box ? std::optional(box->max()[axis]) : std::nullopt);
  }
  insert.run();
}

int read_dimension(const sqlite::Statement& row, int column, const std::string& file,
                   std::int64_t id) {
  const std::int64_t value = row.column_int(column);
  if (value < 0 || value > INT_MAX) damaged(file, id, "impossible grid size");
  return static_cast<int>(value);
}

std::optional<Eigen::AlignedBox3d> read_bbox(const sqlite::Statement& row) {
  if (row.is_null(kBboxMinX)) return std::nullopt;
  const Eigen::Vector3d min(row.column_double(kBboxMinX), row.column_double(kBboxMinY),
                            row.column_double(kBboxMinZ));
  const Eigen::Vector3d max(row.column_double(kBboxMaxX), row.column_double(kBboxMaxY),
                            row.column_double(kBboxMaxZ));
  return Eigen::AlignedBox3d(min, max);
}

StoredScanSummary read_summary(const sqlite::Statement& row, const std::string& file) {
  StoredScanSummary stored;
  stored.id = row.column_int(kId);
  auto& summary = stored.summary;
  summary.name = row.column_text(kName);
  summary.rows = read_dimension(row, kRows, file, stored.id);
  summary.columns = read_dimension(row, kColumns, file, stored.id);
  const std::string model = row.column_text(kAngleModel);
  if (model != "spherical" && model != "per_pixel") damaged(file, stored.id, "unknown angle model");
  summary.spherical = model == "spherical";
  summary.T_world_scan = decode_pose(row.column_blob(kPose), file, stored.id);
  summary.scanner.name = row.column_text(kScannerName);
  summary.scanner.source_file = row.column_text(kSourceFile);
  summary.scanner.position_world = {row.column_double(kScannerX), row.column_double(kScannerY),
                                    row.column_double(kScannerZ)};
  summary.valid_points = static_cast<std::size_t>(row.column_int(kValidPoints));
  summary.has_color = row.column_int(kHasColor) != 0;
  summary.has_intensity = row.column_int(kHasIntensity) != 0;
  summary.bbox_world = read_bbox(row);
  return stored;
}

acquisition::AngleModel read_angles(const sqlite::Statement& row, bool spherical) {
  if (!spherical) return acquisition::PerPixelDirections{};
  return acquisition::SphericalAngles{
      row.column_double(kAzimuthStart), row.column_double(kAzimuthStep),
      row.column_double(kElevationStart), row.column_double(kElevationStep)};
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
  if (scan.has_intensity()) {
    layers.push_back(encode_layer<float>(layer::kIntensity, ElementType::kF32, scan.intensity));
  }
  if (scan.has_color()) {
    layers.push_back(encode_layer<std::uint8_t>(layer::kRgb, ElementType::kU8x3, scan.rgb));
  }
  if (const auto* per_pixel = std::get_if<acquisition::PerPixelDirections>(&scan.angles)) {
    layers.push_back(encode_layer<Eigen::Vector3f>(layer::kDirections, ElementType::kF32x3,
                                                   per_pixel->directions));
    encoded.metadata.angles = acquisition::PerPixelDirections{};
  } else {
    encoded.metadata.angles = scan.angles;
  }
  return encoded;
}

std::size_t Project::stored_pixel_count(std::int64_t id, const Edit* edit) const {
  sqlite::Statement statement(db(), R"sql(
SELECT rows * columns FROM scans
WHERE id = ?1 AND (created_by = ?2 OR created_by IN (SELECT id FROM commands WHERE state = 'done')))sql",
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
  bind_scan_row(insert, edit.command_id(), scan);
  insert.run();
  const std::int64_t id = sqlite3_last_insert_rowid(db());
  insert_pose(db(), file_name(), id, edit.command_id(), scan.metadata.T_world_scan,
              scan.metadata.scanner.position_world, scan.summary.bbox_world);
  for (const EncodedLayer& layer : scan.layers) put_layer(edit, id, layer);
  return id;
}

void Project::set_pose(Edit& edit, std::int64_t id, const acquisition::Scan& scan) {
  check_edit(edit);
  assert(scan.T_world_scan.matrix().allFinite() && "set_pose takes a finite pose");
  [[maybe_unused]] const std::size_t n = stored_pixel_count(id, &edit);  // throws when none
  assert(n == scan.pixel_count() && "set_pose takes the stored scan");
  // The scanner moves with its scan: its position in the scan frame stays.
  const StoredScanSummary before = current_summary(id);
  const Eigen::Vector3d scanner_world = scan.T_world_scan * before.summary.T_world_scan.inverse() *
                                        before.summary.scanner.position_world;
  insert_pose(db(), file_name(), id, edit.command_id(), scan.T_world_scan, scanner_world,
              acquisition::world_bounds(scan));
}

StoredScanSummary Project::current_summary(std::int64_t id) const {
  const std::string sql = std::string(kSelectScans) + " AND s.id = ?1";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  select.bind_int(1, id);
  if (!select.step()) {
    throw core::InputError(file_name(), {}, "no scan with id " + std::to_string(id));
  }
  return read_summary(select, file_name());
}

std::vector<StoredScanSummary> Project::scans() const {
  const std::string sql = std::string(kSelectScans) + " ORDER BY s.id";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  std::vector<StoredScanSummary> result;
  while (select.step()) result.push_back(read_summary(select, file_name()));
  return result;
}

acquisition::Scan Project::load_scan(std::int64_t id) const {
  const std::string sql = std::string(kSelectScans) + " AND s.id = ?1";
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
  scan.angles = read_angles(select, summary.spherical);
  scan.T_world_scan = summary.T_world_scan;
  scan.scanner = summary.scanner;
  scan.range_m = required_layer<float>(*this, id, layer::kRange, ElementType::kF32);
  scan.valid = required_layer<std::uint8_t>(*this, id, layer::kValid, ElementType::kU8);
  if (summary.has_intensity) {
    scan.intensity = required_layer<float>(*this, id, layer::kIntensity, ElementType::kF32);
  }
  if (summary.has_color) {
    scan.rgb = required_layer<std::uint8_t>(*this, id, layer::kRgb, ElementType::kU8x3);
  }
  if (!summary.spherical) {
    std::get<acquisition::PerPixelDirections>(scan.angles).directions =
        required_layer<Eigen::Vector3f>(*this, id, layer::kDirections, ElementType::kF32x3);
  }
  return scan;
}

}  // namespace scanbench::modeling
