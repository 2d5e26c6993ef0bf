#include "acquisition/formats/ply_reader.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/formats/point_cloud.hpp"
#include "acquisition/formats/text_lines.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"
#include "core/text.hpp"

namespace scanbench::acquisition {
namespace {

enum class Body { kAscii, kLittleEndian, kBigEndian };

enum class Type { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

struct Property {
  std::string name;
  Type type = Type::kF32;
  bool list = false;
  Type count_type = Type::kU8;  // lists only
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Body body = Body::kAscii;
  std::vector<Element> elements;
  std::uint64_t body_offset = 0;
};

std::optional<Type> type_named(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, Type>, 16> kTypes = {{
      {"char", Type::kI8},
      {"int8", Type::kI8},
      {"uchar", Type::kU8},
      {"uint8", Type::kU8},
      {"short", Type::kI16},
      {"int16", Type::kI16},
      {"ushort", Type::kU16},
      {"uint16", Type::kU16},
      {"int", Type::kI32},
      {"int32", Type::kI32},
      {"uint", Type::kU32},
      {"uint32", Type::kU32},
      {"float", Type::kF32},
      {"float32", Type::kF32},
      {"double", Type::kF64},
      {"float64", Type::kF64},
  }};
  for (const auto& [text, type] : kTypes) {
    if (text == name) return type;
  }
  return std::nullopt;
}

std::size_t size_of(Type type) {
  switch (type) {
    case Type::kI8:
    case Type::kU8:
      return 1;
    case Type::kI16:
    case Type::kU16:
      return 2;
    case Type::kI32:
    case Type::kU32:
    case Type::kF32:
      return 4;
    case Type::kF64:
      return 8;
  }
  return 0;
}

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

std::uint64_t count_of(TextLineReader& reader, std::string_view text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) {
    reader.fail("element count \"" + std::string(text) + "\" is not a whole number");
  }
  return value;
}

Type type_of(TextLineReader& reader, std::string_view name) {
  const std::optional<Type> type = type_named(name);
  if (!type) reader.fail("unknown property type \"" + std::string(name) + "\"");
  return *type;
}

Header read_header(TextLineReader& reader) {
  std::string_view line;
  if (!reader.next(line) || line != "ply") reader.fail("not a PLY file (no \"ply\" signature)");
  Header h;
  bool format = false;
  while (true) {
    if (!reader.next(line)) reader.fail("header has no end_header line");
    const std::vector<std::string_view> w = words(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") reader.fail("unsupported format line");
      if (w[1] == "ascii") {
        h.body = Body::kAscii;
      } else if (w[1] == "binary_little_endian") {
        h.body = Body::kLittleEndian;
      } else if (w[1] == "binary_big_endian") {
        h.body = Body::kBigEndian;
      } else {
        reader.fail("unknown body format \"" + std::string(w[1]) + "\"");
      }
      format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) reader.fail("an element line needs a name and a count");
      h.elements.push_back({std::string(w[1]), count_of(reader, w[2]), {}});
    } else if (w[0] == "property") {
      if (h.elements.empty()) reader.fail("a property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        p = {std::string(w[4]), type_of(reader, w[3]), true, type_of(reader, w[2])};
      } else if (w.size() == 3) {
        p = {std::string(w[2]), type_of(reader, w[1]), false, Type::kU8};
      } else {
        reader.fail("malformed property line");
      }
      h.elements.back().properties.push_back(std::move(p));
    } else {
      reader.fail("unknown header keyword \"" + std::string(w[0]) + "\"");
    }
  }
  if (!format) reader.fail("header has no format line");
  h.body_offset = reader.bytes_consumed();
  return h;
}

// Where the vertex element's channels are: property indices, -1 for none.
struct Channels {
  int xyz[3] = {-1, -1, -1};
  int rgb[3] = {-1, -1, -1};
  int intensity = -1;
  int normal[3] = {-1, -1, -1};
  int footprint = -1;
};

Channels find_channels(TextLineReader& reader, const Element& vertex) {
  Channels c;
  for (std::size_t k = 0; k < vertex.properties.size(); ++k) {
    const std::string name = core::ascii_lower(vertex.properties[k].name);
    const int index = static_cast<int>(k);
    for (int axis = 0; axis < 3; ++axis) {
      if (name == std::string(1, static_cast<char>('x' + axis))) c.xyz[axis] = index;
    }
    const char* colours[3] = {"red", "green", "blue"};
    for (int channel = 0; channel < 3; ++channel) {
      if (name == colours[channel] || name == std::string("diffuse_") + colours[channel]) {
        c.rgb[channel] = index;
      }
    }
    if (name == "intensity" || name == "scalar_intensity") c.intensity = index;
    for (int axis = 0; axis < 3; ++axis) {
      const char letter = static_cast<char>('x' + axis);
      if (name == std::string("n") + letter || name == std::string("normal_") + letter) {
        c.normal[axis] = index;
      }
    }
    if (name == "radius" || name == "footprint") c.footprint = index;
  }
  for (const int axis : c.xyz) {
    if (axis < 0) reader.fail("the vertex element has no x, y and z properties");
  }
  for (const int k : {c.xyz[0], c.xyz[1], c.xyz[2], c.rgb[0], c.rgb[1], c.rgb[2], c.intensity,
                      c.normal[0], c.normal[1], c.normal[2], c.footprint}) {
    const Property* p = k >= 0 ? &vertex.properties[static_cast<std::size_t>(k)] : nullptr;
    if (p != nullptr && p->list) reader.fail("the vertex property \"" + p->name + "\" is a list");
  }
  if (std::count(c.normal, c.normal + 3, -1) % 3 != 0) {
    reader.fail("the vertex element has some but not all of nx, ny and nz");
  }
  if (std::count(c.rgb, c.rgb + 3, -1) % 3 != 0) {
    reader.fail("the vertex element has some but not all of red, green and blue");
  }
  return c;
}

template <typename T>
T load(const unsigned char* p, bool swap) {
  std::array<unsigned char, sizeof(T)> bytes;
  std::memcpy(bytes.data(), p, sizeof(T));
  if (swap) std::reverse(bytes.begin(), bytes.end());
  return std::bit_cast<T>(bytes);
}

inline double value_at(const unsigned char* p, Type type, bool swap) {
  switch (type) {
    case Type::kI8:
      return static_cast<std::int8_t>(*p);
    case Type::kU8:
      return *p;
    case Type::kI16:
      return load<std::int16_t>(p, swap);
    case Type::kU16:
      return load<std::uint16_t>(p, swap);
    case Type::kI32:
      return load<std::int32_t>(p, swap);
    case Type::kU32:
      return load<std::uint32_t>(p, swap);
    case Type::kF32:
      return load<float>(p, swap);
    case Type::kF64:
      return load<double>(p, swap);
  }
  return 0.0;
}

inline std::uint8_t colour_byte(double value, Type type) {
  if (type == Type::kU8 && value >= 0.0 && value <= 255.0) return static_cast<std::uint8_t>(value);
  double unit = value / 255.0;
  if (type == Type::kU16 || type == Type::kI16) unit = value / 65535.0;
  if (type == Type::kF32 || type == Type::kF64) unit = value;
  return static_cast<std::uint8_t>(std::lround(std::clamp(unit, 0.0, 1.0) * 255.0));
}

// Adds one vertex; value(k) is the value of its property k. False for a
// coordinate beyond kMaxCoordinateM.
template <typename Value>
bool add_vertex(const Element& vertex, const Channels& c, const Value& value, PointCloud& cloud) {
  const Eigen::Vector3d p(value(c.xyz[0]), value(c.xyz[1]), value(c.xyz[2]));
  if (!p.allFinite()) return true;  // no return
  if (!(p.cwiseAbs().maxCoeff() <= kMaxCoordinateM)) return false;
  cloud.points.push_back(p);
  constexpr double kLargest = std::numeric_limits<float>::max();
  const auto as_float = [&](int k) {
    return static_cast<float>(std::clamp(value(k), -kLargest, kLargest));
  };
  if (c.intensity >= 0) cloud.intensity.push_back(as_float(c.intensity));
  if (c.rgb[0] >= 0) {
    for (const int k : c.rgb) {
      cloud.rgb.push_back(
          colour_byte(value(k), vertex.properties[static_cast<std::size_t>(k)].type));
    }
  }
  if (c.normal[0] >= 0) {
    cloud.normal.emplace_back(as_float(c.normal[0]), as_float(c.normal[1]), as_float(c.normal[2]));
  }
  if (c.footprint >= 0) cloud.footprint_m.push_back(as_float(c.footprint));
  return true;
}

constexpr const char* kTooFar = ": coordinate beyond 10^8 m (a corrupt value?)";

void read_ascii(TextLineReader& reader, const Header& h, const Channels& c, PointCloud& cloud) {
  std::string_view line;
  std::vector<double> numbers;
  for (const Element& element : h.elements) {
    const bool is_vertex = element.name == "vertex";
    for (std::uint64_t k = 0; k < element.count; ++k) {
      if (!reader.next(line)) {
        reader.fail("truncated body: " + element.name + " " + std::to_string(k) + " of " +
                    std::to_string(element.count) + " is missing");
      }
      if (!is_vertex) continue;
      numbers.resize(element.properties.size() + 64);
      const int fields = parse_numbers(line, numbers);
      if (fields < 0) reader.fail("a value of vertex " + std::to_string(k) + " is not a number");
      // Values in property order; a list's items are skipped by its count.
      std::vector<double> values(element.properties.size(), 0.0);
      int at = 0;
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        if (at >= std::min(fields, static_cast<int>(numbers.size()))) {
          reader.fail("vertex " + std::to_string(k) + " has too few values");
        }
        values[p] = numbers[static_cast<std::size_t>(at++)];
        if (element.properties[p].list) {
          if (!(values[p] >= 0.0 && values[p] <= static_cast<double>(fields))) {
            reader.fail("vertex " + std::to_string(k) + " has a list of a bad length");
          }
          at += static_cast<int>(values[p]);
        }
      }
      const auto value = [&values](int q) { return values[static_cast<std::size_t>(q)]; };
      if (!add_vertex(element, c, value, cloud)) {
        reader.fail("vertex " + std::to_string(k) + kTooFar);
      }
    }
    if (is_vertex) return;
  }
}

class BinaryBody {
 public:
  BinaryBody(const std::filesystem::path& path, std::uint64_t offset, std::uint64_t size)
      : file_(std::fopen(path.c_str(), "rb")), name_(path.string()), size_(size), at_(offset) {
    if (file_ == nullptr) throw core::RuntimeFailure(name_, {}, "cannot open the file");
    if (std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0) fail("cannot seek");
  }
  ~BinaryBody() { std::fclose(file_); }
  BinaryBody(const BinaryBody&) = delete;
  BinaryBody& operator=(const BinaryBody&) = delete;

  // `bytes` bytes of the body, valid until the next call.
  const unsigned char* take(std::size_t bytes, const std::string& what) {
    if (size_ - at_ < bytes) fail("truncated body: " + what + " is missing");
    buffer_.resize(bytes);
    if (std::fread(buffer_.data(), 1, bytes, file_) != bytes) fail("cannot read " + what);
    at_ += bytes;
    return buffer_.data();
  }

  [[noreturn]] void fail(const std::string& problem) const {
    throw core::InputError(name_, {std::nullopt, at_, ""}, problem);
  }

 private:
  std::FILE* file_;
  std::string name_;
  std::uint64_t size_;
  std::uint64_t at_;
  std::vector<unsigned char> buffer_;
};

std::size_t fixed_record_size(const Element& element) {
  std::size_t size = 0;
  for (const Property& p : element.properties) {
    if (p.list) return 0;
    size += size_of(p.type);
  }
  return size;
}

// One property of a fixed-size record: where it starts, how it is stored.
struct Field {
  std::size_t offset = 0;
  Type type = Type::kF32;
};

// The fields of a fixed-size record, property by property.
std::vector<Field> record_fields(const Element& element) {
  std::vector<Field> fields;
  std::size_t offset = 0;
  for (const Property& p : element.properties) {
    fields.push_back({offset, p.type});
    offset += size_of(p.type);
  }
  return fields;
}

// Appends `count` fixed-size vertex records of `block`, the first being
// vertex `first`: the common case (every exporter writes one), without the
// per-property buffer that records with lists need. Returns the index of
// the first vertex beyond kMaxCoordinateM, if any, which is not appended.
std::optional<std::uint64_t> add_fixed_vertices(const Element& vertex, const Channels& c,
                                                const std::vector<Field>& fields, bool swap,
                                                const unsigned char* block, std::size_t record,
                                                std::uint64_t count, std::uint64_t first,
                                                PointCloud& cloud) {
  for (std::uint64_t k = 0; k < count; ++k) {
    const unsigned char* r = block + k * record;
    const auto value = [&](int q) {
      const Field& f = fields[static_cast<std::size_t>(q)];
      return value_at(r + f.offset, f.type, swap);
    };
    if (!add_vertex(vertex, c, value, cloud)) return first + k;
  }
  return std::nullopt;
}

void read_binary(const std::filesystem::path& path, std::uint64_t file_size, const Header& h,
                 const Channels& c, PointCloud& cloud) {
  const bool swap = (h.body == Body::kBigEndian) != (std::endian::native == std::endian::big);
  BinaryBody body(path, h.body_offset, file_size);
  std::vector<double> values;
  for (const Element& element : h.elements) {
    const bool is_vertex = element.name == "vertex";
    if (element.properties.empty()) continue;  // records of no bytes
    values.assign(element.properties.size(), 0.0);
    const std::size_t fixed = fixed_record_size(element);
    const std::vector<Field> fields = record_fields(element);
    // Fixed-size records in blocks; records with lists one property at a time.
    constexpr std::uint64_t kBlock = 1 << 16;
    for (std::uint64_t first = 0; first < element.count;) {
      const std::string what = element.name + " " + std::to_string(first);
      if (fixed > 0) {
        const std::uint64_t count = std::min(kBlock, element.count - first);
        const unsigned char* block = body.take(fixed * count, what);
        if (is_vertex) {
          if (const auto far =
                  add_fixed_vertices(element, c, fields, swap, block, fixed, count, first, cloud))
            body.fail("vertex " + std::to_string(*far) + kTooFar);
        }
        first += count;
        continue;
      }
      for (std::size_t q = 0; q < element.properties.size(); ++q) {
        const Property& p = element.properties[q];
        if (!p.list) {
          values[q] = value_at(body.take(size_of(p.type), what), p.type, swap);
          continue;
        }
        const double items = value_at(body.take(size_of(p.count_type), what), p.count_type, swap);
        if (!(items >= 0.0 && items < 1e9)) body.fail("a list of " + what + " has a bad count");
        body.take(static_cast<std::size_t>(items) * size_of(p.type), what);
        values[q] = items;
      }
      const auto value = [&values](int q) { return values[static_cast<std::size_t>(q)]; };
      if (is_vertex && !add_vertex(element, c, value, cloud)) {
        body.fail("vertex " + std::to_string(first) + kTooFar);
      }
      ++first;
    }
    if (is_vertex) return;
  }
}

}  // namespace

std::vector<ImportedScan> read_ply(const std::filesystem::path& path) {
  TextLineReader reader(path);
  if (reader.file_size() == 0) reader.fail("empty file");
  const Header header = read_header(reader);
  const auto vertex = std::find_if(header.elements.begin(), header.elements.end(),
                                   [](const Element& e) { return e.name == "vertex"; });
  if (vertex == header.elements.end()) reader.fail("the header has no vertex element");
  // Every record of a body takes a byte (binary, per property) or a line
  // (ASCII): a count beyond the file's size is a damaged header.
  for (auto e = header.elements.begin(); e != std::next(vertex); ++e) {
    const bool empty_binary = header.body != Body::kAscii && e->properties.empty();
    if (e->count > reader.file_size() && !empty_binary) {
      reader.fail("the element \"" + e->name + "\" claims " + std::to_string(e->count) +
                  " records, more than the file's bytes");
    }
  }
  const Channels channels = find_channels(reader, *vertex);
  // A vertex takes at least one byte per property in any body; its point,
  // channels and the scan's layers about 64 bytes.
  if (vertex->count > reader.file_size()) reader.fail("the vertex count exceeds the file's size");
  core::check_memory(vertex->count * 64, reader.file_name());
  PointCloud cloud;
  const std::size_t pixels = scattered_pixel_count(vertex->count);  // the scan pads to its last row
  core::reserve_mapped(cloud.points, pixels);
  if (channels.intensity >= 0) core::reserve_mapped(cloud.intensity, pixels);
  if (channels.rgb[0] >= 0) core::reserve_mapped(cloud.rgb, 3 * pixels);
  if (channels.normal[0] >= 0) core::reserve_mapped(cloud.normal, pixels);
  if (channels.footprint >= 0) core::reserve_mapped(cloud.footprint_m, pixels);
  if (header.body == Body::kAscii) {
    read_ascii(reader, header, channels, cloud);
  } else {
    read_binary(path, reader.file_size(), header, channels, cloud);
  }
  std::vector<ImportedScan> out = scattered_scans(std::move(cloud), path);
  for (ImportedScan& scan : out) {
    scan.source.format = "ply";
    if (out.size() == 1) scan.source.points_in_file = vertex->count;
  }
  return out;
}

}  // namespace scanbench::acquisition
