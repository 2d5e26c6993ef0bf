// The organized scan grid: the one data type every later stage reads.
//
// A scan is a rows × columns grid stored as parallel arrays in row-major
// order (pixel (row, col) is element row * columns + col). Points are not
// stored: a point in the scan frame is range × direction(row, col), where the
// direction comes from the scan's angle model. The pose T_world_scan is kept
// in double precision because georeferenced scans sit at 10^5–10^6 m, where a
// float would lose millimetres.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace scanbench::acquisition {

// The regular panoramic grid of a scanner such as the RIEGL LMS-Z360:
// column `col` looks at azimuth  azimuth_start_rad + col * azimuth_step_rad,
// row `row`   looks at elevation elevation_start_rad + row * elevation_step_rad.
// Steps are signed; the grid convention of the source file is kept as it is.
// Direction in the scan frame (z up):
//   (cos(el) cos(az), cos(el) sin(az), sin(el)).
struct SphericalAngles {
  double azimuth_start_rad = 0.0;
  double azimuth_step_rad = 0.0;
  double elevation_start_rad = 0.0;
  double elevation_step_rad = 0.0;

  // Of column `col` and row `row` [rad]: every direction is computed from
  // these, so that directions computed apart agree bit for bit.
  double azimuth(int col) const { return azimuth_start_rad + col * azimuth_step_rad; }
  double elevation(int row) const { return elevation_start_rad + row * elevation_step_rad; }

  friend bool operator==(const SphericalAngles&, const SphericalAngles&) = default;
};

// Irregular grids (structured light, resampled clouds): one unit direction per
// pixel, row-major, in the scan frame. A pixel whose direction is unknown (no
// return and no model to predict it) holds the zero vector.
//
// A scattered scan is an unstructured cloud (E57 without row and column
// indices, LAS, PLY, unorganized PCD) kept whole: its points fill the
// pixels 0 … n − 1 in the file's order, the rest of the last row is
// invalid, and neighbouring pixels are not neighbouring points. Projecting
// such a cloud into a panorama would drop every point that falls on a
// pixel a nearer one holds (a quarter of a scanned object, or of a cloud
// unified from several stations); storing it as a list loses nothing, and
// every stage that works on points (geometry from the k nearest
// neighbours, registration, merge, rendering, export) works on it. The
// tools that need a range image (seed, lasso, barrier) refuse it.
struct PerPixelDirections {
  std::vector<Eigen::Vector3f> directions;
  bool scattered = false;

  friend bool operator==(const PerPixelDirections&, const PerPixelDirections&) = default;
};

using AngleModel = std::variant<SphericalAngles, PerPixelDirections>;

struct ScannerMetadata {
  std::string name;         // scanner model or instrument id; empty when unknown
  std::string source_file;  // file the scan was imported from (UTF-8 path)
  // Registered scanner position in the world frame [m], as the source file gives it.
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
};

struct Scan {
  std::string name;  // UTF-8, for people: the file stem for imported scans; not unique
  int rows = 0;
  int columns = 0;

  // Channels, all rows * columns long (rgb three times that), row-major.
  std::vector<float> range_m;       // distance from the scanner [m]; meaningful where valid
  std::vector<std::uint8_t> valid;  // 1 = a return, 0 = no return (sky, dropout, "0 0 0")
  std::vector<float> intensity;     // empty when the source has none; else as the source gives it
  std::vector<std::uint8_t> rgb;    // empty when the source has none; else 8-bit R, G, B per pixel

  AngleModel angles = SphericalAngles{};
  Eigen::Isometry3d T_world_scan = Eigen::Isometry3d::Identity();
  ScannerMetadata scanner;
  // How far [m] a point of the file the scan was read from lies from where
  // the scan puts it, at most (LocalOriginResult::max_error_m, set by the
  // reader): within 0.1 mm unless the points spread beyond float ranges'
  // reach (about 900 m around their centroid). 0 for scans not placed from
  // points. Not stored with the scan; ScanSource::round_trip_error_m is.
  double import_round_trip_m = 0.0;

  std::size_t pixel_count() const { return static_cast<std::size_t>(rows) * columns; }
  std::size_t index(int row, int col) const {
    return static_cast<std::size_t>(row) * columns + col;
  }
  bool has_intensity() const { return !intensity.empty(); }
  bool has_color() const { return !rgb.empty(); }
  bool is_spherical() const { return std::holds_alternative<SphericalAngles>(angles); }
  bool is_scattered() const {
    const auto* per_pixel = std::get_if<PerPixelDirections>(&angles);
    return per_pixel != nullptr && per_pixel->scattered;
  }
};

// Per-point geometry a file recorded beside its points (a PLY's nx, ny, nz
// and radius, a LAS's NormalX, NormalY, NormalZ and Footprint extra bytes,
// as our exports write them), per pixel of a scattered scan. Each vector is
// empty when the file has none, else pixel_count() long: a unit normal in
// the scan frame, the zero vector where the file gives none, and a
// footprint radius [m], 0 where none. The geometry stage keeps them
// (scattered_geometry.hpp): they may come from a better neighbourhood than
// the cloud still has (the scan grid it was exported from, a mesh).
struct RecordedGeometry {
  std::vector<Eigen::Vector3f> normal;
  std::vector<float> footprint_m;

  bool empty() const { return normal.empty() && footprint_m.empty(); }
};

// `scan` without its per-pixel arrays (channels, per-pixel directions),
// which are left empty: its name, grid size, angle model, pose, scanner
// and round-trip error. For code that keeps a scan's arrays elsewhere (a
// spill file) and its description in memory; a field added to Scan is
// copied here.
Scan without_arrays(const Scan& scan);

// Allocates every channel of a rows × columns scan: range 0, all pixels
// invalid, intensity / rgb only when requested. Asserts rows, columns ≥ 0.
Scan make_empty_scan(int rows, int columns, bool with_intensity, bool with_color);

// A scattered scan of `points` points (PerPixelDirections::scattered): a
// grid about as wide as tall whose first `points` pixels are valid, range
// 0, directions zero, intensity / rgb only when requested. The caller
// fills the channels of pixel k with the cloud's k-th point, then the
// geometry (set_grid_from_points). Asserts points < 2^31 · 2^31.
Scan make_scattered_scan(std::size_t points, bool with_intensity, bool with_color);

// The pixels of such a scan: its points and the padding of its last row.
std::size_t scattered_pixel_count(std::size_t points);

// Readers refuse coordinates farther than this from their file's origin
// [m]: no survey reaches them (UTM northings stay below 10^7 m), and a
// corrupt value or scale would otherwise pass as a point.
inline constexpr double kMaxCoordinateM = 1e8;

// Unit viewing direction of pixel (row, col) in the scan frame. For per-pixel
// grids this is the stored direction (zero when unknown). Every per-pixel
// accessor below asserts 0 ≤ row < rows and 0 ≤ col < columns.
Eigen::Vector3f direction(const Scan& scan, int row, int col);

// direction() of every pixel of a spherical grid (std::get: the scan must
// have one), from each
// row's and column's sines and cosines computed once: the same vectors, bit
// for bit, at the cost of a few multiplications, for loops that need the
// directions of a scan's pixels again and again.
class SphericalDirections {
 public:
  explicit SphericalDirections(const Scan& scan);
  Eigen::Vector3f operator()(int row, int col) const { return precise(row, col).cast<float>(); }
  // direction_precise's, bit for bit.
  Eigen::Vector3d precise(int row, int col) const {
    assert(row >= 0 && static_cast<std::size_t>(row) < rows_.size() && col >= 0 &&
           static_cast<std::size_t>(col) < columns_.size());
    const Eigen::Vector2d& el = rows_[static_cast<std::size_t>(row)];
    const Eigen::Vector2d& az = columns_[static_cast<std::size_t>(col)];
    return {el.x() * az.x(), el.x() * az.y(), el.y()};
  }

 private:
  std::vector<Eigen::Vector2d> rows_;     // cos, sin of each row's elevation
  std::vector<Eigen::Vector2d> columns_;  // cos, sin of each column's azimuth
};

// The same direction in double precision, normalised in double (per-pixel
// directions are re-normalised), for exporters and world coordinates.
// Where `scan` holds a band of a grid's rows from grid row `first_row`
// (acquisition/geometry/row_band.hpp), `row` counts the held rows and the
// direction is the grid's, bit for bit.
Eigen::Vector3d direction_precise(const Scan& scan, int row, int col, int first_row = 0);

// Point of pixel (row, col) in the scan frame [m]; meaningless where !valid.
Eigen::Vector3f point_in_scan(const Scan& scan, int row, int col);

// Point of pixel (row, col) in the world frame [m], in double precision;
// `first_row` as for direction_precise.
Eigen::Vector3d point_in_world(const Scan& scan, int row, int col, int first_row = 0);

// True when the scan's columns close the full circle of azimuth (a
// spherical grid whose columns × |azimuth step| is 2π within half a step):
// then column 0 neighbours the last column. False for per-pixel grids.
bool wraps_around(const Scan& scan);

// Number of pixels with a return (valid != 0).
std::size_t count_valid(const Scan& scan);

// The intensities of the pixels `usable` marks (finite ones) at the 2nd and
// 98th percentile: the spread a scan's intensities really take, unswayed by
// a few retro-reflectors. {0, 1} when the scan has fewer than 2 such values.
// Asserts usable.size() == pixel_count() when the scan has intensity.
std::pair<float, float> intensity_range(const Scan& scan, const std::vector<std::uint8_t>& usable);

// Axis-aligned bounds of the valid points in the world frame [m]; empty
// optional when the scan has no valid point.
std::optional<Eigen::AlignedBox3d> world_bounds(const Scan& scan);
// The same with the scan at `T_world_scan` instead of its own pose.
std::optional<Eigen::AlignedBox3d> world_bounds(const Scan& scan,
                                                const Eigen::Isometry3d& T_world_scan);

// Checks the channel sizes against rows × columns and the angle model; used by
// writers and the project before storing. Returns an empty string when the
// scan is consistent, else a description of the first inconsistency.
std::string check_consistency(const Scan& scan);

}  // namespace scanbench::acquisition
