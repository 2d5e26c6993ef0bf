#include "acquisition/formats/pcd_header.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>

#include "acquisition/rigid_transform.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::uint64_t kMaxSide = 1'000'000;
constexpr std::uint64_t kMaxPoints = std::uint64_t{1} << 31;
constexpr std::uint64_t kMaxHeaderLines = 1000;
constexpr std::uint64_t kMaxCount = 4096;  // values per field (PCL's largest descriptors: ~1000)
constexpr std::size_t kMaxFields = 1000;

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t start = 0;
  while ((start = line.find_first_not_of(" \t\r", start)) != std::string_view::npos) {
    const std::size_t end = std::min(line.find_first_of(" \t\r", start), line.size());
    tokens.push_back(line.substr(start, end - start));
    start = end;
  }
  return tokens;
}

std::optional<std::uint64_t> unsigned_of(std::string_view token) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

// A token cut to about 40 characters for messages.
std::string shown(std::string_view token) {
  return token.size() <= 40 ? std::string(token) : std::string(token.substr(0, 40)) + "…";
}

// What the header lines say, before the checks that need all of them.
struct Lines {
  std::vector<std::string_view> names;
  std::vector<std::uint64_t> sizes, counts;
  std::vector<char> types;
  std::optional<std::uint64_t> width, height, points;
  std::vector<double> viewpoint;
  std::optional<std::string> data;
  std::vector<std::string> storage;  // owns the names: reader lines do not live on
};

std::vector<std::uint64_t> numbers_of(TextLineReader& reader,
                                      const std::vector<std::string_view>& tokens) {
  std::vector<std::uint64_t> values;
  for (std::size_t i = 1; i < tokens.size(); ++i) {
    const auto v = unsigned_of(tokens[i]);
    const bool ok = v && (tokens[0] == "SIZE" ? (*v == 1 || *v == 2 || *v == 4 || *v == 8)
                                              : (*v >= 1 && *v <= kMaxCount));
    if (!ok) reader.fail(std::string(tokens[0]) + " value " + shown(tokens[i]) + " is absurd");
    values.push_back(*v);
  }
  return values;
}

std::vector<char> types_of(TextLineReader& reader, const std::vector<std::string_view>& tokens) {
  std::vector<char> types;
  for (std::size_t i = 1; i < tokens.size(); ++i) {
    if (tokens[i] != "I" && tokens[i] != "U" && tokens[i] != "F") {
      reader.fail("TYPE value " + shown(tokens[i]) + " is not I, U or F");
    }
    types.push_back(tokens[i][0]);
  }
  return types;
}

std::vector<double> viewpoint_of(TextLineReader& reader,
                                 const std::vector<std::string_view>& tokens) {
  if (tokens.size() != 8) reader.fail("VIEWPOINT needs 7 numbers (tx ty tz qw qx qy qz)");
  std::vector<double> values;
  for (std::size_t i = 1; i < tokens.size(); ++i) {
    double value = 0;
    const auto [end, error] =
        std::from_chars(tokens[i].data(), tokens[i].data() + tokens[i].size(), value);
    if (error != std::errc() || end != tokens[i].data() + tokens[i].size()) {
      reader.fail("VIEWPOINT value '" + shown(tokens[i]) + "' is not a number");
    }
    if (!std::isfinite(value) || std::abs(value) > std::numeric_limits<float>::max()) {
      reader.fail("VIEWPOINT has a non-finite value");
    }
    values.push_back(value);
  }
  return values;
}

// Returns true at the DATA line, which ends the header.
bool read_line(TextLineReader& reader, const std::vector<std::string_view>& tokens, Lines& h) {
  const std::string_view key = tokens[0];
  const auto single = [&](std::optional<std::uint64_t>& out) {
    out = tokens.size() == 2 ? unsigned_of(tokens[1]) : std::nullopt;
    if (!out) reader.fail(std::string(key) + " is not a non-negative integer");
  };
  if (key == "FIELDS" || key == "COLUMNS") {
    if (tokens.size() - 1 > kMaxFields) reader.fail("more than 1000 FIELDS");
    h.storage.assign(tokens.begin() + 1, tokens.end());
    h.names.assign(h.storage.begin(), h.storage.end());
  } else if (key == "SIZE" || key == "COUNT") {
    (key == "SIZE" ? h.sizes : h.counts) = numbers_of(reader, tokens);
  } else if (key == "TYPE") {
    h.types = types_of(reader, tokens);
  } else if (key == "WIDTH") {
    single(h.width);
  } else if (key == "HEIGHT") {
    single(h.height);
  } else if (key == "POINTS") {
    single(h.points);
  } else if (key == "VIEWPOINT") {
    h.viewpoint = viewpoint_of(reader, tokens);
  } else if (key == "DATA") {
    if (tokens.size() != 2) reader.fail("DATA line needs exactly one type");
    h.data = std::string(tokens[1]);
    return true;
  } else if (key != "VERSION") {
    reader.fail("unexpected line in PCD header (not a PCD file?)");
  }
  return false;
}

Lines read_lines(TextLineReader& reader) {
  Lines h;
  std::string_view line;
  while (reader.line_number() < kMaxHeaderLines && reader.next(line)) {
    const std::vector<std::string_view> tokens = split(line);
    if (tokens.empty() || tokens[0].front() == '#') continue;
    if (read_line(reader, tokens, h)) return h;
  }
  reader.fail("no DATA line in the header (not a PCD file?)");
}

std::vector<PcdField> fields_of(TextLineReader& reader, const Lines& h) {
  if (h.names.empty()) reader.fail("header has no FIELDS");
  const std::size_t n = h.names.size();
  const auto agrees = [n](std::size_t size) { return size == 0 || size == n; };
  if (!agrees(h.sizes.size()) || !agrees(h.counts.size()) || !agrees(h.types.size())) {
    reader.fail("SIZE, TYPE or COUNT disagrees with FIELDS in length");
  }
  std::vector<PcdField> fields(n);
  std::uint64_t offset = 0, column = 0;
  for (std::size_t i = 0; i < n; ++i) {
    PcdField& f = fields[i];
    f.name = std::string(h.names[i]);
    if (!h.sizes.empty()) f.size = h.sizes[i];
    if (!h.types.empty()) f.type = h.types[i];
    if (!h.counts.empty()) f.count = h.counts[i];
    if (f.type == 'F' && f.size != 4 && f.size != 8) {
      reader.fail("field " + f.name + " is a float of " + std::to_string(f.size) + " bytes");
    }
    f.offset = offset;
    f.column = column;
    offset += f.size * f.count;
    column += f.count;
  }
  return fields;
}

void check_dimensions(TextLineReader& reader, const Lines& h, PcdHeader& out) {
  if (!h.points) reader.fail("header has no POINTS line");
  out.points = *h.points;
  out.height = h.height.value_or(1);
  out.width = h.width.value_or(out.points);
  if (out.width == 0 || out.height == 0 || out.points == 0) {
    reader.fail("empty point cloud (no points)");
  }
  // An unorganized cloud (HEIGHT 1) is one row of any length.
  const bool organized = out.height > 1;
  if ((organized && out.width > kMaxSide) || out.height > kMaxSide || out.points > kMaxPoints) {
    reader.fail("absurd dimensions (more than 1000000 a side or 2^31 points)");
  }
  if (out.width * out.height != out.points) {
    reader.fail("WIDTH x HEIGHT (" + std::to_string(out.width) + " x " +
                std::to_string(out.height) + ") disagrees with POINTS (" +
                std::to_string(out.points) + ")");
  }
}

Eigen::Isometry3d pose_of(TextLineReader& reader, const std::vector<double>& v) {
  if (v.empty()) return Eigen::Isometry3d::Identity();
  const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
  if (std::abs(q.norm() - 1.0) > kRigidTolerance) {
    reader.fail("VIEWPOINT quaternion is not unit (norm " + std::to_string(q.norm()) + ")");
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  m.topRightCorner<3, 1>() = Eigen::Vector3d(v[0], v[1], v[2]);
  if (const std::string problem = rigid_transform_problem(m); !problem.empty()) {
    reader.fail("VIEWPOINT: " + problem);
  }
  return to_isometry(m);
}

PcdData data_of(TextLineReader& reader, const std::string& data) {
  if (data == "ascii") return PcdData::kAscii;
  if (data == "binary") return PcdData::kBinary;
  if (data == "binary_compressed") return PcdData::kBinaryCompressed;
  reader.fail("unknown DATA type '" + shown(data) + "'");
}

}  // namespace

PcdHeader read_pcd_header(TextLineReader& reader) {
  const Lines lines = read_lines(reader);
  PcdHeader header;
  header.data = data_of(reader, *lines.data);
  header.fields = fields_of(reader, lines);
  for (const PcdField& f : header.fields) {
    header.point_step += f.size * f.count;
    header.values_per_point += f.count;
  }
  check_dimensions(reader, lines, header);
  header.viewpoint = pose_of(reader, lines.viewpoint);
  header.body_offset = reader.bytes_consumed();
  return header;
}

const PcdField* find_field(const PcdHeader& header, std::string_view name) {
  for (const PcdField& field : header.fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

}  // namespace scanbench::acquisition
