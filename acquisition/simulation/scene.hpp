// The virtual world the simulated scanner looks at: analytic primitives
// (parallelograms, boxes, cylinders, spheres, triangles) with an object id and
// a material each, an object hierarchy, and a bounding-volume hierarchy for
// exact, thread-safe ray casting.
//
// Everything is in the world frame, in metres, z up.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace scanbench::acquisition::sim {

using ObjectId = std::uint16_t;   // 0 means "no object" (sky, no return)
using MaterialId = std::uint16_t;

// Procedural surface patterns; the pattern functions live in textures.hpp.
enum class Pattern : std::uint8_t {
  kFlat,      // the base albedo, unmodulated
  kBrick,     // running bond with mortar joints; texture_scale_m = brick length
  kPlaster,   // fine mottled noise
  kStone,     // irregular blocks
  kWood,      // grain stripes along u
  kGlass,     // dark, slightly reflective
  kAsphalt,   // speckled dark grey, lane markings not included
  kGrass,     // green noise
  kBark,      // vertical furrows
  kFoliage,   // leafy noise
  kPaint,     // glossy uniform (car body)
  kMetal,     // brushed
  kConcrete,  // light grey blotches
  kImage,     // an RGB image stretched over the surface (signs with lettering)
};

struct Material {
  std::string name;
  Eigen::Vector3f albedo{0.5f, 0.5f, 0.5f};  // linear RGB base colour, [0, 1]
  float reflectance = 0.5f;  // at the laser wavelength, [0, 1]; drives intensity
  Pattern pattern = Pattern::kFlat;
  float texture_scale_m = 1.0f;  // size of one repeat of the pattern [m]
  int image = -1;                // index into Scene::images() for Pattern::kImage
};

// An RGB image for Pattern::kImage, row 0 at the top, linear RGB in [0, 1],
// mapped onto uv ∈ [0, width_m] × [0, height_m] of the surface (u right, v up).
struct TextureImage {
  int rows = 0;
  int columns = 0;
  std::vector<Eigen::Vector3f> rgb;  // rows × columns, row-major
  double width_m = 1.0;
  double height_m = 1.0;
};

// origin + s · edge_u + t · edge_v for s, t ∈ [0, 1]; two-sided.
// Texture coordinates: uv_m = (s · |edge_u|, t · |edge_v|).
struct Quad {
  Eigen::Vector3d origin;
  Eigen::Vector3d edge_u;
  Eigen::Vector3d edge_v;
};

// Solid box rotated by yaw_rad about the vertical axis through its centre.
// Texture coordinates on each face: metres along the face's two edges,
// horizontal edge first (vertical faces), x then y (top and bottom).
struct Box {
  Eigen::Vector3d center;
  Eigen::Vector3d half_extent;
  double yaw_rad = 0.0;
};

// Solid vertical cylinder with flat caps. Texture coordinates on the side:
// (arc length from azimuth 0 [m], height above the base [m]).
struct Cylinder {
  Eigen::Vector3d base_center;
  double radius = 0.0;
  double height = 0.0;
};

// Texture coordinates: (longitude · radius, latitude · radius) [m].
struct Sphere {
  Eigen::Vector3d center;
  double radius = 0.0;
};

// Two-sided triangle (terrain meshes). Texture coordinates: world (x, y) [m].
struct Triangle {
  Eigen::Vector3d a;
  Eigen::Vector3d b;
  Eigen::Vector3d c;
};

using Shape = std::variant<Quad, Box, Cylinder, Sphere, Triangle>;

struct Primitive {
  Shape shape;
  ObjectId object = 0;
  MaterialId material = 0;
};

// A node of the ground-truth hierarchy: site → building → wall / door /
// window, trees → trunk / crown, ground tiles, lamp posts, car, low wall.
struct ObjectInfo {
  ObjectId id = 0;
  std::string name;
  ObjectId parent = 0;  // 0 for the site root itself
  std::string kind;     // "site", "building", "wall", "door", "window", "roof", "tree", …
};

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit
};

struct Hit {
  double distance_m = 0.0;  // along the ray's unit direction
  Eigen::Vector3d normal;   // unit geometric normal, facing the ray origin
  Eigen::Vector2d uv_m;     // surface texture coordinates [m]
  ObjectId object = 0;
  MaterialId material = 0;
};

class Scene {
 public:
  // The site root gets id 1; later objects get consecutive ids.
  ObjectId add_object(std::string name, ObjectId parent, std::string kind);
  MaterialId add_material(Material material);
  int add_image(TextureImage image);
  // Asserts `object` and `material` exist and the shape is non-degenerate.
  void add(const Shape& shape, ObjectId object, MaterialId material);

  // Builds the bounding-volume hierarchy. Call once after the last add() and
  // before intersect(); adding afterwards asserts.
  void build();

  // Nearest hit with distance in [min_distance_m, max_distance_m], or none.
  // Thread-safe after build(). Asserts build() was called.
  std::optional<Hit> intersect(const Ray& ray, double min_distance_m, double max_distance_m) const;

  const std::vector<ObjectInfo>& objects() const { return objects_; }
  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<TextureImage>& images() const { return images_; }
  const std::vector<Primitive>& primitives() const { return primitives_; }
  const ObjectInfo& object(ObjectId id) const { return objects_.at(id - 1); }
  Eigen::AlignedBox3d bounds() const;

 private:
  struct Node {
    Eigen::AlignedBox3d box;
    std::uint32_t first = 0;  // first primitive (leaf) or left child index (inner)
    std::uint32_t count = 0;  // primitives in a leaf; 0 for an inner node
  };
  std::uint32_t build_node(std::uint32_t begin, std::uint32_t end);

  std::vector<ObjectInfo> objects_;
  std::vector<Material> materials_;
  std::vector<TextureImage> images_;
  std::vector<Primitive> primitives_;
  std::vector<Node> nodes_;
  bool built_ = false;
};

// Exact ray/shape intersection: the nearest hit of `ray` with `shape` at a
// distance in [min_distance_m, max_distance_m]; normal and uv as documented
// on each shape. Used by Scene and by tests.
std::optional<Hit> intersect_shape(const Shape& shape, const Ray& ray, double min_distance_m,
                                   double max_distance_m);

// World-space bounds of a shape.
Eigen::AlignedBox3d shape_bounds(const Shape& shape);

}  // namespace scanbench::acquisition::sim
