#include "acquisition/formats/ptx_reader.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include "acquisition/formats/text_lines.hpp"
#include "acquisition/local_origin.hpp"
#include "acquisition/rigid_transform.hpp"
#include "core/memory.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::int64_t kMaxDimension = 1'000'000;
// Coordinates beyond this [m] are no place on or near the Earth (geocentric
// coordinates stay within 10^7 m): a corrupt value, refused before it makes a
// range that no float holds.
constexpr std::int64_t kMaxPixels = std::int64_t{1} << 31;
constexpr std::uint64_t kMinPointLineBytes = 8;  // "0 0 0 0\n"

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::int64_t parse_dimension(TextLineReader& reader, std::string_view line, const char* what,
                             const char* hint = "") {
  line = trim(line);
  std::int64_t value = 0;
  const auto [stop, error] = std::from_chars(line.data(), line.data() + line.size(), value);
  if (error != std::errc() || stop != line.data() + line.size()) {
    reader.fail(std::string("expected the ") + what + " count, an integer; found \"" +
                std::string(line.substr(0, 40)) + "\"" + hint);
  }
  if (value <= 0 || value > kMaxDimension) {
    reader.fail("dimension " + std::to_string(value) + " is out of range (1 to 1000000)");
  }
  return value;
}

// Reads a header line of exactly `count` finite numbers into `out`.
void read_fixed_line(TextLineReader& reader, std::span<double> out, const char* what) {
  std::string_view line;
  if (!reader.next(line)) reader.fail(std::string("file ends inside the header (") + what + ")");
  const int fields = parse_numbers(line, out);
  if (fields < 0) reader.fail(std::string("non-numeric, NaN or infinite value in ") + what);
  if (static_cast<std::size_t>(fields) != out.size()) {
    reader.fail(std::string(what) + " needs " + std::to_string(out.size()) + " numbers, found " +
                std::to_string(fields));
  }
}

// Scan header after the two dimension lines: scanner position, scanner axes
// (informative only: the 4x4 transform is the pose) and the transform.
void read_pose(TextLineReader& reader, Scan& scan) {
  std::array<double, 3> position{}, axis{};
  read_fixed_line(reader, position, "scanner position");
  for (const char* what : {"scanner x axis", "scanner y axis", "scanner z axis"}) {
    read_fixed_line(reader, axis, what);
  }
  Eigen::Matrix4d m;
  for (int column = 0; column < 4; ++column) {
    std::array<double, 4> values{};
    read_fixed_line(reader, values, "transform");
    for (int row = 0; row < 4; ++row) m(row, column) = values[row];
  }
  if (const std::string problem = rigid_transform_problem(m); !problem.empty())
    reader.fail(problem);
  scan.T_world_scan = to_isometry(m);
  scan.scanner.position_world = Eigen::Vector3d(position[0], position[1], position[2]);
}

std::uint8_t color_channel(TextLineReader& reader, double value) {
  if (value < 0 || value > 255 || value != std::floor(value)) {
    reader.fail("colour value must be an integer from 0 to 255");
  }
  return static_cast<std::uint8_t>(value);
}

// Reads rows · columns point lines into `scan` (channels already sized) and
// `points` (scan frame, for the angle fit).
void read_points(TextLineReader& reader, Scan& scan, std::vector<Eigen::Vector3d>& points) {
  const std::size_t n = scan.pixel_count();
  std::array<double, 7> v{};
  int expected_fields = 0;
  for (std::size_t k = 0; k < n; ++k) {
    std::string_view line;
    if (!reader.next(line)) {
      reader.fail("file is truncated: scan \"" + scan.name + "\" declares " + std::to_string(n) +
                  " points, found " + std::to_string(k));
    }
    const int fields = parse_numbers(line, v);
    if (fields < 0) reader.fail("non-numeric, NaN or infinite value in a point line");
    if (std::abs(v[0]) > kMaxCoordinateM || std::abs(v[1]) > kMaxCoordinateM ||
        std::abs(v[2]) > kMaxCoordinateM) {
      reader.fail("coordinate beyond 10^8 m (a corrupt value?)");
    }
    if (std::abs(v[3]) > std::numeric_limits<float>::max()) {
      reader.fail("intensity does not fit a float");
    }
    if (expected_fields == 0) {
      if (fields != 4 && fields != 7) {
        reader.fail("a point line needs 4 (x y z intensity) or 7 (with r g b) fields, found " +
                    std::to_string(fields));
      }
      expected_fields = fields;
      if (fields == 7) scan.rgb.assign(3 * n, 0);
    } else if (fields != expected_fields) {
      reader.fail("point line has " + std::to_string(fields) + " fields, the scan's first has " +
                  std::to_string(expected_fields) + " (or the header dimensions are wrong)");
    }
    const std::size_t i =
        scan.index(static_cast<int>(k % scan.rows), static_cast<int>(k / scan.rows));
    points[i] = Eigen::Vector3d(v[0], v[1], v[2]);
    scan.valid[i] = !points[i].isZero(0.0);
    scan.intensity[i] = static_cast<float>(v[3]);
    if (expected_fields == 7) {
      for (int c = 0; c < 3; ++c) scan.rgb[3 * i + c] = color_channel(reader, v[4 + c]);
    }
  }
}

// Skips blank lines; returns false at the end of the file.
bool next_nonblank(TextLineReader& reader, std::string_view& line) {
  while (reader.next(line)) {
    if (!trim(line).empty()) return true;
  }
  return false;
}

}  // namespace

void read_ptx(const std::filesystem::path& path, const PtxReadSettings& settings,
              const std::function<void(Scan&&)>& on_scan) {
  TextLineReader reader(path);
  if (reader.file_size() == 0) reader.fail("file is empty");
  const std::string stem = path.stem().string();
  std::string_view line;
  int scan_index = 0;
  for (; next_nonblank(reader, line); ++scan_index) {
    const std::int64_t columns = parse_dimension(
        reader, line, "column",
        scan_index == 0 ? "" : " (or the previous scan has more points than its header declares)");
    if (!reader.next(line)) reader.fail("file ends after the column count");
    const std::int64_t rows = parse_dimension(reader, line, "row");
    if (rows * columns > kMaxPixels) reader.fail("rows x columns exceeds 2^31 points");
    const std::uint64_t remaining = reader.file_size() - reader.bytes_consumed();
    if (static_cast<std::uint64_t>(rows * columns) * kMinPointLineBytes > remaining) {
      reader.fail(std::to_string(rows) + " x " + std::to_string(columns) +
                  " points cannot fit in the " + std::to_string(remaining) +
                  " bytes left in the file (truncated file or wrong header)");
    }
    // The scan's channels and colour, and the points in double while the
    // angle model is fitted: 48 bytes per pixel at most.
    core::check_memory(static_cast<std::uint64_t>(rows * columns) * 48, reader.file_name());
    Scan scan = make_empty_scan(static_cast<int>(rows), static_cast<int>(columns), true, false);
    scan.name = scan_index == 0 ? stem : stem + "-" + std::to_string(scan_index + 1);
    scan.scanner.source_file = path.string();
    read_pose(reader, scan);
    std::vector<Eigen::Vector3d> points(scan.pixel_count(), Eigen::Vector3d::Zero());
    read_points(reader, scan, points);
    // The header's scanner position is the centre of projection of scans
    // whose points are already in world coordinates.
    const Eigen::Vector3d centre_file = scan.T_world_scan.inverse() * scan.scanner.position_world;
    set_grid_from_points(scan, points, centre_file, settings.grid);
    on_scan(std::move(scan));
  }
  if (scan_index == 0) reader.fail("file holds no scan (only blank lines)");
}

std::vector<Scan> read_ptx(const std::filesystem::path& path, const PtxReadSettings& settings) {
  std::vector<Scan> scans;
  read_ptx(path, settings, [&scans](Scan&& scan) { scans.push_back(std::move(scan)); });
  return scans;
}

}  // namespace scanbench::acquisition
