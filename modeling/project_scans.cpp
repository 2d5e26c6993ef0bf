// The scans and scan_channels tables: Project::insert_scan, scans, load_scan.
#include <array>
#include <bit>
#include <cassert>
#include <climits>
#include <cstring>

#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"
#include "modeling/project.hpp"
#include "modeling/project_channels.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {

namespace {

static_assert(std::endian::native == std::endian::little,
              "poses are stored as little-endian doubles");

// Column order of kSelectScans; also the parameter numbers of kInsertScan.
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
  kPose,
  kScannerName,
  kSourceFile,
  kScannerX,
  kScannerY,
  kScannerZ,
  kValidPoints,
  kHasColor,
  kHasIntensity,
  kBboxMinX,
  kBboxMinY,
  kBboxMinZ,
  kBboxMaxX,
  kBboxMaxY,
  kBboxMaxZ,
};

constexpr const char* kScanColumns = R"sql(
  name, rows, columns, angle_model,
  azimuth_start_rad, azimuth_step_rad, elevation_start_rad, elevation_step_rad,
  T_world_scan, scanner_name, source_file, scanner_x, scanner_y, scanner_z,
  valid_points, has_color, has_intensity,
  bbox_min_x, bbox_min_y, bbox_min_z, bbox_max_x, bbox_max_y, bbox_max_z)sql";

const std::string kSelectScans = std::string("SELECT id, ") + kScanColumns + " FROM scans";

const std::string kInsertScan = std::string("INSERT INTO scans (") + kScanColumns +
                                ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, "
                                "?13, ?14, ?15, ?16, ?17, ?18, ?19, ?20, ?21, ?22, ?23)";

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

void bind_scan_row(sqlite::Statement& insert, const acquisition::Scan& scan,
                   const acquisition::ScanSummary& summary,
                   std::span<const std::uint8_t> pose_bytes) {
  insert.bind_text(kName, scan.name).bind_int(kRows, scan.rows).bind_int(kColumns, scan.columns);
  insert.bind_text(kAngleModel, acquisition::angle_model_name(scan.is_spherical()));
  const auto* angles = std::get_if<acquisition::SphericalAngles>(&scan.angles);
  const auto angle = [&](double acquisition::SphericalAngles::*field) {
    return angles != nullptr ? std::optional<double>(angles->*field) : std::nullopt;
  };
  insert
      .bind_optional_double(kAzimuthStart, angle(&acquisition::SphericalAngles::azimuth_start_rad))
      .bind_optional_double(kAzimuthStep, angle(&acquisition::SphericalAngles::azimuth_step_rad))
      .bind_optional_double(kElevationStart,
                            angle(&acquisition::SphericalAngles::elevation_start_rad))
      .bind_optional_double(kElevationStep,
                            angle(&acquisition::SphericalAngles::elevation_step_rad));
  insert.bind_blob(kPose, pose_bytes).bind_text(kScannerName, scan.scanner.name);
  insert.bind_text(kSourceFile, scan.scanner.source_file);
  for (int axis = 0; axis < 3; ++axis) {
    insert.bind_double(kScannerX + axis, scan.scanner.position_world[axis]);
  }
  insert.bind_int(kValidPoints, static_cast<std::int64_t>(summary.valid_points))
      .bind_int(kHasColor, summary.has_color)
      .bind_int(kHasIntensity, summary.has_intensity);
  for (int axis = 0; axis < 3; ++axis) {
    const auto& box = summary.bbox_world;
    insert
        .bind_optional_double(kBboxMinX + axis,
                              box ? std::optional(box->min()[axis]) : std::nullopt)
        .bind_optional_double(kBboxMaxX + axis,
                              box ? std::optional(box->max()[axis]) : std::nullopt);
  }
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

}  // namespace

std::int64_t Project::insert_scan(const acquisition::Scan& scan) {
  assert(sqlite3_get_autocommit(db()) == 0 && "insert_scan needs an open Project::Transaction");
  assert(acquisition::check_consistency(scan).empty() &&
         "insert_scan needs a consistent scan (see acquisition::check_consistency)");
  const acquisition::ScanSummary summary = acquisition::summarize(scan);
  const auto pose_bytes = encode_pose(scan.T_world_scan);
  sqlite::Statement insert(db(), kInsertScan.c_str(), file_name());
  bind_scan_row(insert, scan, summary, pose_bytes);
  insert.run();
  const std::int64_t id = sqlite3_last_insert_rowid(db());
  insert_channels(db(), file_name(), id, scan);
  return id;
}

void Project::update_pose(std::int64_t id, const acquisition::Scan& scan) {
  assert(sqlite3_get_autocommit(db()) == 0 && "update_pose needs an open Project::Transaction");
  const acquisition::ScanSummary summary = acquisition::summarize(scan);
  const auto pose_bytes = encode_pose(scan.T_world_scan);
  sqlite::Statement update(db(), R"sql(
UPDATE scans SET T_world_scan = ?2, scanner_x = ?3, scanner_y = ?4, scanner_z = ?5,
  bbox_min_x = ?6, bbox_min_y = ?7, bbox_min_z = ?8, bbox_max_x = ?9, bbox_max_y = ?10,
  bbox_max_z = ?11
WHERE id = ?1 AND rows = ?12 AND columns = ?13)sql",
                           file_name());
  update.bind_int(1, id).bind_blob(2, pose_bytes);
  const Eigen::Vector3d origin = scan.T_world_scan.translation();
  for (int axis = 0; axis < 3; ++axis) update.bind_double(3 + axis, origin[axis]);
  const auto& box = summary.bbox_world;
  for (int axis = 0; axis < 3; ++axis) {
    update.bind_optional_double(6 + axis, box ? std::optional(box->min()[axis]) : std::nullopt)
        .bind_optional_double(9 + axis, box ? std::optional(box->max()[axis]) : std::nullopt);
  }
  update.bind_int(12, scan.rows).bind_int(13, scan.columns).run();
  if (sqlite3_changes(db()) != 1) {
    throw core::InputError(file_name(), {},
                           "no scan with id " + std::to_string(id) + " of that size");
  }
}

std::vector<StoredScanSummary> Project::scans() const {
  const std::string sql = kSelectScans + " ORDER BY id";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  std::vector<StoredScanSummary> result;
  while (select.step()) result.push_back(read_summary(select, file_name()));
  return result;
}

acquisition::Scan Project::load_scan(std::int64_t id) const {
  const std::string sql = kSelectScans + " WHERE id = ?1";
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
  read_channels(db(), file_name(), id, summary.has_intensity, summary.has_color, scan);
  return scan;
}

}  // namespace scanbench::modeling
