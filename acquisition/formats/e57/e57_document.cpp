#include "acquisition/formats/e57/e57_document.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <pugixml.hpp>
#include <sstream>

#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

constexpr const char* kNamespace = "http://www.astm.org/COMMIT/E57/2010-e57-v1.0";

// Parsing context: the file name for errors.
struct Parser {
  const std::string& file;

  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    core::FilePosition position;
    position.detail = "XML element " + (path.empty() ? std::string("/") : path);
    throw core::InputError(file, position, problem);
  }

  pugi::xml_node child(pugi::xml_node node, const std::string& path, const char* name,
                       const char* type, bool required) const {
    const pugi::xml_node found = node.child(name);
    if (!found) {
      if (required) fail(path, std::string("lacks the required element \"") + name + "\"");
      return found;
    }
    if (std::string_view(found.attribute("type").value()) != type) {
      fail(path + "/" + name, std::string("has type \"") + found.attribute("type").value() +
                                  "\" where E57 requires " + type);
    }
    return found;
  }

  // `text` without the white space around it.
  static std::string_view trimmed(const char* text) {
    std::string_view view(text);
    while (!view.empty() && std::isspace(static_cast<unsigned char>(view.front())))
      view.remove_prefix(1);
    while (!view.empty() && std::isspace(static_cast<unsigned char>(view.back())))
      view.remove_suffix(1);
    return view;
  }

  std::int64_t integer_text(const char* text, const std::string& path) const {
    const std::string_view view = trimmed(text);
    if (view.empty()) return 0;
    std::int64_t value = 0;
    const auto [end, error] = std::from_chars(view.data(), view.data() + view.size(), value);
    if (error != std::errc() || end != view.data() + view.size()) {
      fail(path, "holds \"" + std::string(view) + "\", not a 64-bit integer");
    }
    return value;
  }

  double float_text(const char* text, const std::string& path) const {
    const std::string_view view = trimmed(text);
    if (view.empty()) return 0.0;
    double value = 0.0;
    const auto [end, error] = std::from_chars(view.data(), view.data() + view.size(), value);
    if (error != std::errc() || end != view.data() + view.size() || !std::isfinite(value)) {
      fail(path, "holds \"" + std::string(view) + "\", not a finite number");
    }
    return value;
  }

  // An element's whole text: every text and CDATA child, joined (a writer
  // may split a string over several, as "]]>" must be).
  static std::string text_of(pugi::xml_node node) {
    std::string text;
    for (pugi::xml_node part : node.children()) {
      if (part.type() == pugi::node_pcdata || part.type() == pugi::node_cdata) text += part.value();
    }
    return text;
  }

  // The value of an Integer element, exactly; `fallback` when absent and
  // not required.
  std::int64_t integer(pugi::xml_node node, const std::string& path, const char* name,
                       std::int64_t fallback, bool required) const {
    const pugi::xml_node found = child(node, path, name, "Integer", required);
    return found ? integer_text(text_of(found).c_str(), path + "/" + name) : fallback;
  }

  // The value of a number element of any of the three number types.
  double number(pugi::xml_node node, const std::string& path, const char* name, double fallback,
                bool required = false) const {
    const pugi::xml_node found = node.child(name);
    const std::string where = path + "/" + name;
    if (!found) {
      if (required) fail(path, std::string("lacks the required element \"") + name + "\"");
      return fallback;
    }
    const std::string_view type = found.attribute("type").value();
    const std::string text = text_of(found);
    if (type == "Float") return float_text(text.c_str(), where);
    if (type == "Integer") return static_cast<double>(integer_text(text.c_str(), where));
    if (type == "ScaledInteger") {
      const double scale = attribute_float(found, where, "scale", 1.0);
      const double offset = attribute_float(found, where, "offset", 0.0);
      return static_cast<double>(integer_text(text.c_str(), where)) * scale + offset;
    }
    fail(where, "has type \"" + std::string(type) + "\" where E57 requires a number");
  }

  std::string string(pugi::xml_node node, const std::string& path, const char* name) const {
    const pugi::xml_node found = child(node, path, name, "String", false);
    return found ? text_of(found) : "";
  }

  std::int64_t attribute_integer(pugi::xml_node node, const std::string& path, const char* name,
                                 std::int64_t fallback) const {
    const pugi::xml_attribute attribute = node.attribute(name);
    if (!attribute) return fallback;
    return integer_text(attribute.value(), path + "@" + name);
  }

  double attribute_float(pugi::xml_node node, const std::string& path, const char* name,
                         double fallback) const {
    const pugi::xml_attribute attribute = node.attribute(name);
    if (!attribute) return fallback;
    return float_text(attribute.value(), path + "@" + name);
  }

  Eigen::Isometry3d pose(pugi::xml_node node, const std::string& path) const {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    const pugi::xml_node found = child(node, path, "pose", "Structure", false);
    if (!found) return pose;
    const std::string where = path + "/pose";
    if (const pugi::xml_node rotation = child(found, where, "rotation", "Structure", false)) {
      const std::string at = where + "/rotation";
      Eigen::Quaterniond q(number(rotation, at, "w", 1.0), number(rotation, at, "x", 0.0),
                           number(rotation, at, "y", 0.0), number(rotation, at, "z", 0.0));
      if (!(q.norm() > 0.5 && q.norm() < 1.5)) fail(at, "is not a unit quaternion");
      pose.linear() = q.normalized().toRotationMatrix();
    }
    if (const pugi::xml_node translation = child(found, where, "translation", "Structure", false)) {
      const std::string at = where + "/translation";
      pose.translation() =
          Eigen::Vector3d(number(translation, at, "x", 0.0), number(translation, at, "y", 0.0),
                          number(translation, at, "z", 0.0));
    }
    return pose;
  }

  E57Field field(pugi::xml_node node, const std::string& path) const {
    E57Field field;
    field.name = node.name();
    const std::string_view type = node.attribute("type").value();
    constexpr std::int64_t kLowest = std::numeric_limits<std::int64_t>::min();
    constexpr std::int64_t kHighest = std::numeric_limits<std::int64_t>::max();
    if (type == "Float") {
      field.type = E57FieldType::kFloat;
      const std::string_view precision = node.attribute("precision").value();
      if (!precision.empty() && precision != "single" && precision != "double") {
        fail(path, "has precision \"" + std::string(precision) + "\" (single or double)");
      }
      field.single_precision = precision == "single";
      field.float_minimum = attribute_float(node, path, "minimum", -HUGE_VAL);
      field.float_maximum = attribute_float(node, path, "maximum", HUGE_VAL);
      return field;
    }
    if (type != "Integer" && type != "ScaledInteger") {
      fail(path, "is a point field of type \"" + std::string(type) +
                     "\"; scanbench reads Integer, ScaledInteger and Float fields");
    }
    field.type = type == "Integer" ? E57FieldType::kInteger : E57FieldType::kScaledInteger;
    field.minimum = attribute_integer(node, path, "minimum", kLowest);
    field.maximum = attribute_integer(node, path, "maximum", kHighest);
    if (field.maximum < field.minimum) fail(path, "has a maximum below its minimum");
    if (field.type == E57FieldType::kScaledInteger) {
      field.scale = attribute_float(node, path, "scale", 1.0);
      field.offset = attribute_float(node, path, "offset", 0.0);
      if (field.scale == 0.0) fail(path, "has a scale of 0");
    }
    return field;
  }

  // The prototype's terminal fields, depth first, in document order;
  // structures nest at most kMaxDepth deep.
  void prototype_fields(pugi::xml_node node, const std::string& path, std::vector<E57Field>& fields,
                        int depth = 0) const {
    constexpr int kMaxDepth = 8;
    if (depth > kMaxDepth) fail(path, "nests structures deeper than scanbench reads (8)");
    for (pugi::xml_node element : node.children()) {
      if (element.type() != pugi::node_element) continue;
      const std::string where = path + "/" + element.name();
      if (std::string_view(element.attribute("type").value()) == "Structure") {
        prototype_fields(element, where, fields, depth + 1);
      } else {
        fields.push_back(field(element, where));
      }
    }
  }

  E57ScanEntry scan(pugi::xml_node node, const std::string& path) const {
    E57ScanEntry entry;
    entry.path = path;
    entry.guid = string(node, path, "guid");
    entry.name = string(node, path, "name");
    entry.description = string(node, path, "description");
    entry.sensor_model = string(node, path, "sensorModel");
    entry.pose = pose(node, path);
    if (const pugi::xml_node bounds = child(node, path, "indexBounds", "Structure", false)) {
      const std::string at = path + "/indexBounds";
      const auto get = [&](const char* name, bool required) {
        return integer(bounds, at, name, 0, required);
      };
      entry.index_bounds = E57IndexBounds{get("rowMinimum", true),     get("rowMaximum", true),
                                          get("columnMinimum", true),  get("columnMaximum", true),
                                          get("returnMinimum", false), get("returnMaximum", false)};
    }
    if (const pugi::xml_node limits = child(node, path, "intensityLimits", "Structure", false)) {
      const std::string at = path + "/intensityLimits";
      entry.intensity_limits = {number(limits, at, "intensityMinimum", 0.0, true),
                                number(limits, at, "intensityMaximum", 0.0, true)};
    }
    if (const pugi::xml_node limits = child(node, path, "colorLimits", "Structure", false)) {
      const std::string at = path + "/colorLimits";
      std::array<std::pair<double, double>, 3> channels;
      const char* names[3][2] = {{"colorRedMinimum", "colorRedMaximum"},
                                 {"colorGreenMinimum", "colorGreenMaximum"},
                                 {"colorBlueMinimum", "colorBlueMaximum"}};
      for (int c = 0; c < 3; ++c) {
        channels[c] = {number(limits, at, names[c][0], 0.0, true),
                       number(limits, at, names[c][1], 0.0, true)};
      }
      entry.color_limits = channels;
    }
    const pugi::xml_node points = child(node, path, "points", "CompressedVector", true);
    const std::string at = path + "/points";
    const std::int64_t offset = attribute_integer(points, at, "fileOffset", -1);
    const std::int64_t records = attribute_integer(points, at, "recordCount", -1);
    if (offset < 0 || records < 0) fail(at, "lacks a valid fileOffset or recordCount");
    entry.points.file_offset = static_cast<std::uint64_t>(offset);
    entry.points.record_count = static_cast<std::uint64_t>(records);
    const pugi::xml_node prototype = child(points, at, "prototype", "Structure", true);
    prototype_fields(prototype, at + "/prototype", entry.points.fields);
    const pugi::xml_node codecs = points.child("codecs");
    if (codecs && codecs.first_child().type() == pugi::node_element) {
      fail(at + "/codecs", "names a codec; scanbench reads the default bit-pack codec only");
    }
    return entry;
  }

  E57ImageEntry image(pugi::xml_node node, const std::string& path) const {
    E57ImageEntry entry;
    entry.path = path;
    entry.image.guid = string(node, path, "guid");
    entry.image.name = string(node, path, "name");
    entry.associated_scan_guid = string(node, path, "associatedData3DGuid");
    entry.image.T_world_image = pose(node, path);
    struct Kind {
      const char* element;
      ImageProjection projection;
    };
    const Kind kinds[] = {{"pinholeRepresentation", ImageProjection::kPinhole},
                          {"sphericalRepresentation", ImageProjection::kSpherical},
                          {"cylindricalRepresentation", ImageProjection::kCylindrical},
                          {"visualReferenceRepresentation", ImageProjection::kVisualReference}};
    for (const Kind& kind : kinds) {
      const pugi::xml_node representation = child(node, path, kind.element, "Structure", false);
      if (!representation) continue;
      representation_fields(representation, path + "/" + kind.element, kind.projection, entry);
      return entry;
    }
    fail(path, "has no pinhole, spherical, cylindrical or visual-reference representation");
  }

  void representation_fields(pugi::xml_node node, const std::string& path,
                             ImageProjection projection, E57ImageEntry& entry) const {
    ScanImage& image = entry.image;
    image.projection = projection;
    pugi::xml_node blob = child(node, path, "jpegImage", "Blob", false);
    image.format = "jpeg";
    if (!blob) {
      blob = child(node, path, "pngImage", "Blob", false);
      image.format = "png";
    }
    if (!blob) fail(path, "has neither a jpegImage nor a pngImage");
    const std::string at = path + "/" + blob.name();
    const std::int64_t offset = attribute_integer(blob, at, "fileOffset", -1);
    const std::int64_t length = attribute_integer(blob, at, "length", -1);
    if (offset < 0 || length < 0) fail(at, "lacks a valid fileOffset or length");
    entry.blob_offset = static_cast<std::uint64_t>(offset);
    entry.blob_length = static_cast<std::uint64_t>(length);
    constexpr std::int64_t kMaxSide = 1 << 20;
    const std::int64_t width = integer(node, path, "imageWidth", 0, true);
    const std::int64_t height = integer(node, path, "imageHeight", 0, true);
    if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide) {
      fail(path, "has an image of " + std::to_string(width) + " × " + std::to_string(height) +
                     " pixels (1 to 2^20 a side)");
    }
    image.width = static_cast<int>(width);
    image.height = static_cast<int>(height);
    image.pixel_width = number(node, path, "pixelWidth", 0.0);
    image.pixel_height = number(node, path, "pixelHeight", 0.0);
    image.focal_length = number(node, path, "focalLength", 0.0);
    image.principal_x = number(node, path, "principalPointX", 0.0);
    image.principal_y = number(node, path, "principalPointY", 0.0);
    image.radius = number(node, path, "radius", 0.0);
  }
};

}  // namespace

const E57Field* E57PointsEntry::field(std::string_view name) const {
  for (const E57Field& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

E57Document parse_e57_xml(std::string_view xml, const std::string& file) {
  pugi::xml_document tree;
  const pugi::xml_parse_result parsed =
      tree.load_buffer(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!parsed) {
    core::FilePosition position;
    position.detail = "XML section, character " + std::to_string(parsed.offset);
    throw core::InputError(file, position, std::string("malformed XML: ") + parsed.description());
  }
  const Parser parser{file};
  const pugi::xml_node root = tree.child("e57Root");
  if (!root || std::string_view(root.attribute("type").value()) != "Structure") {
    parser.fail("", "the XML section has no e57Root structure");
  }
  E57Document document;
  document.guid = parser.string(root, "", "guid");
  document.coordinate_metadata = parser.string(root, "", "coordinateMetadata");
  if (const pugi::xml_node data3d = parser.child(root, "", "data3D", "Vector", false)) {
    std::size_t k = 0;
    for (pugi::xml_node entry : data3d.children("vectorChild")) {
      document.scans.push_back(parser.scan(entry, "/data3D/" + std::to_string(k++)));
    }
  }
  if (const pugi::xml_node images = parser.child(root, "", "images2D", "Vector", false)) {
    std::size_t k = 0;
    for (pugi::xml_node entry : images.children("vectorChild")) {
      document.images.push_back(parser.image(entry, "/images2D/" + std::to_string(k++)));
    }
  }
  return document;
}

}  // namespace scanbench::acquisition

namespace scanbench::acquisition {
namespace {

// Builds elements of the E57 node types.
struct Builder {
  static pugi::xml_node element(pugi::xml_node parent, const char* name, const char* type) {
    pugi::xml_node node = parent.append_child(name);
    node.append_attribute("type") = type;
    return node;
  }
  static void string(pugi::xml_node parent, const char* name, const std::string& value) {
    pugi::xml_node node = element(parent, name, "String");
    // pugixml splits a "]]>" across two CDATA sections itself.
    if (!value.empty()) node.append_child(pugi::node_cdata).set_value(value.c_str());
  }
  static void real(pugi::xml_node parent, const char* name, double value) {
    element(parent, name, "Float").text() = fmt::format("{}", value).c_str();
  }
  static void integer(pugi::xml_node parent, const char* name, std::int64_t value) {
    element(parent, name, "Integer").text() = fmt::format("{}", value).c_str();
  }
  static void pose(pugi::xml_node parent, const Eigen::Isometry3d& pose) {
    pugi::xml_node node = element(parent, "pose", "Structure");
    const Eigen::Quaterniond q(pose.linear());
    pugi::xml_node rotation = element(node, "rotation", "Structure");
    real(rotation, "w", q.w());
    real(rotation, "x", q.x());
    real(rotation, "y", q.y());
    real(rotation, "z", q.z());
    pugi::xml_node translation = element(node, "translation", "Structure");
    real(translation, "x", pose.translation().x());
    real(translation, "y", pose.translation().y());
    real(translation, "z", pose.translation().z());
  }
  static void field(pugi::xml_node parent, const E57Field& field) {
    switch (field.type) {
      case E57FieldType::kFloat: {
        pugi::xml_node node = element(parent, field.name.c_str(), "Float");
        node.append_attribute("precision") = field.single_precision ? "single" : "double";
        node.append_attribute("minimum") = fmt::format("{}", field.float_minimum).c_str();
        node.append_attribute("maximum") = fmt::format("{}", field.float_maximum).c_str();
        return;
      }
      case E57FieldType::kInteger:
      case E57FieldType::kScaledInteger: {
        const bool scaled = field.type == E57FieldType::kScaledInteger;
        pugi::xml_node node =
            element(parent, field.name.c_str(), scaled ? "ScaledInteger" : "Integer");
        node.append_attribute("minimum") = fmt::format("{}", field.minimum).c_str();
        node.append_attribute("maximum") = fmt::format("{}", field.maximum).c_str();
        if (scaled) {
          node.append_attribute("scale") = fmt::format("{}", field.scale).c_str();
          node.append_attribute("offset") = fmt::format("{}", field.offset).c_str();
        }
        return;
      }
    }
  }
};

void write_scan(pugi::xml_node parent, const E57ScanEntry& scan) {
  pugi::xml_node node = Builder::element(parent, "vectorChild", "Structure");
  Builder::string(node, "guid", scan.guid);
  Builder::string(node, "name", scan.name);
  if (!scan.description.empty()) Builder::string(node, "description", scan.description);
  if (!scan.sensor_model.empty()) Builder::string(node, "sensorModel", scan.sensor_model);
  Builder::pose(node, scan.pose);
  if (scan.index_bounds) {
    const E57IndexBounds& b = *scan.index_bounds;
    pugi::xml_node bounds = Builder::element(node, "indexBounds", "Structure");
    Builder::integer(bounds, "rowMinimum", b.row_minimum);
    Builder::integer(bounds, "rowMaximum", b.row_maximum);
    Builder::integer(bounds, "columnMinimum", b.column_minimum);
    Builder::integer(bounds, "columnMaximum", b.column_maximum);
    Builder::integer(bounds, "returnMinimum", b.return_minimum);
    Builder::integer(bounds, "returnMaximum", b.return_maximum);
  }
  if (scan.intensity_limits) {
    pugi::xml_node limits = Builder::element(node, "intensityLimits", "Structure");
    Builder::real(limits, "intensityMinimum", scan.intensity_limits->first);
    Builder::real(limits, "intensityMaximum", scan.intensity_limits->second);
  }
  if (scan.color_limits) {
    pugi::xml_node limits = Builder::element(node, "colorLimits", "Structure");
    const char* names[3][2] = {{"colorRedMinimum", "colorRedMaximum"},
                               {"colorGreenMinimum", "colorGreenMaximum"},
                               {"colorBlueMinimum", "colorBlueMaximum"}};
    for (int c = 0; c < 3; ++c) {
      Builder::integer(limits, names[c][0],
                       static_cast<std::int64_t>((*scan.color_limits)[c].first));
      Builder::integer(limits, names[c][1],
                       static_cast<std::int64_t>((*scan.color_limits)[c].second));
    }
  }
  pugi::xml_node points = Builder::element(node, "points", "CompressedVector");
  points.append_attribute("fileOffset") = fmt::format("{}", scan.points.file_offset).c_str();
  points.append_attribute("recordCount") = fmt::format("{}", scan.points.record_count).c_str();
  pugi::xml_node prototype = Builder::element(points, "prototype", "Structure");
  for (const E57Field& field : scan.points.fields) Builder::field(prototype, field);
  Builder::element(points, "codecs", "Vector").append_attribute("allowHeterogeneousChildren") = "1";
}

const char* representation_name(ImageProjection projection) {
  switch (projection) {
    case ImageProjection::kPinhole:
      return "pinholeRepresentation";
    case ImageProjection::kSpherical:
      return "sphericalRepresentation";
    case ImageProjection::kCylindrical:
      return "cylindricalRepresentation";
    case ImageProjection::kVisualReference:
      return "visualReferenceRepresentation";
  }
  return "visualReferenceRepresentation";
}

void write_image(pugi::xml_node parent, const E57ImageEntry& entry) {
  const ScanImage& image = entry.image;
  pugi::xml_node node = Builder::element(parent, "vectorChild", "Structure");
  Builder::string(node, "guid", image.guid);
  Builder::string(node, "name", image.name);
  if (!entry.associated_scan_guid.empty()) {
    Builder::string(node, "associatedData3DGuid", entry.associated_scan_guid);
  }
  Builder::pose(node, image.T_world_image);
  const char* kind = representation_name(image.projection);
  pugi::xml_node representation = Builder::element(node, kind, "Structure");
  pugi::xml_node blob =
      Builder::element(representation, image.format == "png" ? "pngImage" : "jpegImage", "Blob");
  blob.append_attribute("fileOffset") = fmt::format("{}", entry.blob_offset).c_str();
  blob.append_attribute("length") = fmt::format("{}", entry.blob_length).c_str();
  Builder::integer(representation, "imageWidth", image.width);
  Builder::integer(representation, "imageHeight", image.height);
  if (image.projection != ImageProjection::kVisualReference) {
    Builder::real(representation, "pixelWidth", image.pixel_width);
    Builder::real(representation, "pixelHeight", image.pixel_height);
  }
  if (image.projection == ImageProjection::kPinhole) {
    Builder::real(representation, "focalLength", image.focal_length);
    Builder::real(representation, "principalPointX", image.principal_x);
  }
  if (image.projection == ImageProjection::kPinhole ||
      image.projection == ImageProjection::kCylindrical) {
    Builder::real(representation, "principalPointY", image.principal_y);
  }
  if (image.projection == ImageProjection::kCylindrical) {
    Builder::real(representation, "radius", image.radius);
  }
}

}  // namespace

std::string write_e57_xml(const E57Document& document) {
  pugi::xml_document tree;
  pugi::xml_node root = Builder::element(tree, "e57Root", "Structure");
  root.append_attribute("xmlns") = kNamespace;
  Builder::string(root, "formatName", "ASTM E57 3D Imaging Data File");
  Builder::string(root, "guid", document.guid);
  Builder::integer(root, "versionMajor", 1);
  Builder::integer(root, "versionMinor", 0);
  Builder::string(root, "e57LibraryVersion", "scanbench");
  Builder::string(root, "coordinateMetadata", document.coordinate_metadata);
  pugi::xml_node data3d = Builder::element(root, "data3D", "Vector");
  data3d.append_attribute("allowHeterogeneousChildren") = "0";
  for (const E57ScanEntry& scan : document.scans) write_scan(data3d, scan);
  pugi::xml_node images = Builder::element(root, "images2D", "Vector");
  images.append_attribute("allowHeterogeneousChildren") = "0";
  for (const E57ImageEntry& image : document.images) write_image(images, image);
  std::ostringstream out;
  tree.save(out, "  ", pugi::format_default | pugi::format_no_declaration, pugi::encoding_utf8);
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n" + out.str();
}

}  // namespace scanbench::acquisition
