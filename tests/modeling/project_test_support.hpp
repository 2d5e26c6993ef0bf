// Hand-built scans and raw SQLite access shared by the project tests.
#pragma once

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>

#include "acquisition/scan.hpp"
#include "core/progress.hpp"
#include "modeling/import_command.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::test {

// Imports `files` into `project` as one command, without progress output.
inline modeling::ImportResult import_files(const std::filesystem::path& project,
                                           std::vector<std::filesystem::path> files) {
  core::Progress quiet;
  return modeling::import_scan_files(project, files, {}, quiet);
}

// A georeferenced pose (10^5-10^6 m) whose rotation holds a -0.0, so that a
// round trip through the project must keep every bit.
inline Eigen::Isometry3d georeferenced_pose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(std::numbers::pi / 6, Eigen::Vector3d::UnitZ()).matrix();
  pose.linear()(2, 0) = -0.0;
  pose.translation() = Eigen::Vector3d(512345.123456789, 5412345.987654321, 312.5);
  return pose;
}

// rows x columns scan with every second pixel valid, ranges 1.5 m + 0.25 m per
// pixel (NaN where invalid), and the optional channels filled with distinct
// values. Spherical grids start at azimuth -0.0.
inline acquisition::Scan tiny_scan(bool spherical, bool with_intensity, bool with_color,
                                   int rows = 2, int columns = 3) {
  acquisition::Scan scan = acquisition::make_empty_scan(rows, columns, with_intensity, with_color);
  scan.name = spherical ? "station 1 é" : "kinect frame";
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    scan.valid[i] = i % 2 == 0;
    scan.range_m[i] = scan.valid[i] ? 1.5f + 0.25f * static_cast<float>(i) : std::nanf("");
    if (with_intensity) scan.intensity[i] = -0.5f + 0.1f * static_cast<float>(i);
    for (std::size_t c = 0; with_color && c < 3; ++c) scan.rgb[3 * i + c] = (i * 40 + c * 7) % 256;
  }
  if (spherical) {
    scan.angles = acquisition::SphericalAngles{-0.0, 0.01, -0.5, 1.0e-3};
  } else {
    acquisition::PerPixelDirections per_pixel;
    for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
      per_pixel.directions.push_back(
          Eigen::Vector3f(0.1f * static_cast<float>(i), -0.2f, 1.0f).normalized());
    }
    if (!per_pixel.directions.empty()) {
      per_pixel.directions.back() = Eigen::Vector3f::Zero();  // unknown direction
    }
    scan.angles = per_pixel;
  }
  scan.T_world_scan = georeferenced_pose();
  scan.scanner.name = "RIEGL LMS-Z360";
  scan.scanner.source_file = "/data/site é/scan 1.ptx";
  scan.scanner.position_world = Eigen::Vector3d(512345.1, 5412345.2, -0.0);
  return scan;
}

// Stores `scan` as a command of its own ("import") and returns its id.
inline std::int64_t insert_committed(store::Project& project, const acquisition::Scan& scan) {
  store::Project::Edit edit = project.begin_command("import", "{}");
  const std::int64_t id = project.insert_scan(edit, store::encode_scan(scan));
  edit.commit("{}");
  return id;
}

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return false;
  return a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

template <typename T>
bool same_bytes(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Bit-for-bit equality of everything a Scan holds.
inline void expect_identical(const acquisition::Scan& a, const acquisition::Scan& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.rows, b.rows);
  EXPECT_EQ(a.columns, b.columns);
  EXPECT_TRUE(same_bytes(a.range_m, b.range_m));
  EXPECT_TRUE(same_bytes(a.valid, b.valid));
  EXPECT_TRUE(same_bytes(a.intensity, b.intensity));
  EXPECT_TRUE(same_bytes(a.rgb, b.rgb));
  ASSERT_EQ(a.is_spherical(), b.is_spherical());
  if (a.is_spherical()) {
    EXPECT_TRUE(same_bytes(std::get<acquisition::SphericalAngles>(a.angles),
                           std::get<acquisition::SphericalAngles>(b.angles)));
  } else {
    EXPECT_TRUE(same_bytes(std::get<acquisition::PerPixelDirections>(a.angles).directions,
                           std::get<acquisition::PerPixelDirections>(b.angles).directions));
  }
  const Eigen::Matrix4d pose_a = a.T_world_scan.matrix();
  const Eigen::Matrix4d pose_b = b.T_world_scan.matrix();
  EXPECT_TRUE(same_bytes(pose_a, pose_b));
  EXPECT_EQ(a.scanner.name, b.scanner.name);
  EXPECT_EQ(a.scanner.source_file, b.scanner.source_file);
  EXPECT_TRUE(same_bytes(a.scanner.position_world, b.scanner.position_world));
}

// A plain SQLite connection, for what the Project API must not offer:
// building other applications' databases and tampering with projects.
class RawDatabase {
 public:
  explicit RawDatabase(const std::filesystem::path& file) {
    const int code =
        sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
    EXPECT_EQ(code, SQLITE_OK) << file;
  }
  ~RawDatabase() { sqlite3_close(db_); }
  RawDatabase(const RawDatabase&) = delete;
  RawDatabase& operator=(const RawDatabase&) = delete;

  void execute(const std::string& sql) {
    char* message = nullptr;
    EXPECT_EQ(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message), SQLITE_OK)
        << sql << ": " << (message ? message : "");
    sqlite3_free(message);
  }

  // First column of the first row as text; empty when there is no row.
  std::string text(const std::string& sql) {
    sqlite3_stmt* statement = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement, nullptr), SQLITE_OK) << sql;
    std::string value;
    if (statement != nullptr && sqlite3_step(statement) == SQLITE_ROW) {
      const auto* chars = sqlite3_column_text(statement, 0);
      if (chars != nullptr) value = reinterpret_cast<const char*>(chars);
    }
    sqlite3_finalize(statement);
    return value;
  }

 private:
  sqlite3* db_ = nullptr;
};

// True when SQLite left none of its side files beside `file`.
inline bool no_side_files(const std::filesystem::path& file) {
  for (const char* suffix : {"-journal", "-wal", "-shm"}) {
    if (std::filesystem::exists(file.string() + suffix)) return false;
  }
  return true;
}

}  // namespace scanbench::test
