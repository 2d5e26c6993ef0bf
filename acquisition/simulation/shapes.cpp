// Exact analytic ray/shape intersection for the simulated scanner's primitives.
//
// Every test works in double precision and returns the nearest surface point
// inside the closed distance window [lo, hi]. Solid shapes (box, cylinder,
// sphere) are hit on their entry surface from outside and on their exit
// surface when the ray starts inside (or when the window begins past the
// entry). Quads and triangles are two-sided. Rays tangent to a surface, or
// lying in a flat surface's plane, graze it and miss: no normal could face
// the ray origin there.
//
// Methods: parallelogram and triangle by the plane equation with barycentric
// coordinates (Möller & Trumbore, "Fast, minimum storage ray/triangle
// intersection", 1997); box by the slab method (Kay & Kajiya 1986) in the
// box's yawed frame; sphere and cylinder side by the quadratic with the
// discriminant written as r² − |perpendicular offset|², which keeps its
// precision for rays far from the centre (Haines et al., "Precision
// Improvements for Ray/Sphere Intersection", Ray Tracing Gems, 2019).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <type_traits>
#include <variant>

#include "acquisition/simulation/scene.hpp"

namespace scanbench::acquisition::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// A flat surface seen within this cosine of edge-on is treated as parallel:
// the hit distance and barycentrics would be dominated by rounding.
constexpr double kParallelCosine = 1e-12;

bool in_window(double t, double lo, double hi) {
  return t >= lo && t <= hi;
}

// Turns `unit_normal` to face the ray origin. A normal exactly perpendicular to
// the ray is a graze, reported as a miss so that every hit satisfies
// dot(normal, direction) < 0.
std::optional<Hit> make_hit(double t, const Vector3d& unit_normal, const Vector3d& direction,
                            const Vector2d& uv_m) {
  const double cosine = unit_normal.dot(direction);
  if (cosine == 0.0) return std::nullopt;
  Hit hit;
  hit.distance_m = t;
  hit.normal = cosine < 0.0 ? unit_normal : Vector3d(-unit_normal);
  hit.uv_m = uv_m;
  return hit;
}

std::optional<Hit> intersect_quad(const Quad& quad, const Ray& ray, double lo, double hi) {
  const Vector3d n = quad.edge_u.cross(quad.edge_v);
  const double n_squared = n.squaredNorm();
  const double denom = n.dot(ray.direction);
  if (denom * denom <= kParallelCosine * kParallelCosine * n_squared) return std::nullopt;
  const double t = n.dot(quad.origin - ray.origin) / denom;
  if (!in_window(t, lo, hi)) return std::nullopt;
  // w = s·edge_u + r·edge_v; crossing with one edge isolates the other coordinate.
  const Vector3d w = ray.origin + t * ray.direction - quad.origin;
  const double s = w.cross(quad.edge_v).dot(n) / n_squared;
  const double r = quad.edge_u.cross(w).dot(n) / n_squared;
  if (s < 0.0 || s > 1.0 || r < 0.0 || r > 1.0) return std::nullopt;
  const Vector2d uv(s * quad.edge_u.norm(), r * quad.edge_v.norm());
  return make_hit(t, n / std::sqrt(n_squared), ray.direction, uv);
}

// Rotation by `yaw` about z, applied forwards (box → world) or inverted.
Vector3d yaw_rotate(const Vector3d& v, double c, double s) {
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()};
}

// Texture coordinates on the box face perpendicular to local `axis`, measured
// from the face's corner with the smallest local coordinates.
Vector2d box_face_uv(const Vector3d& p, const Vector3d& half, int axis) {
  const Vector3d q = p + half;
  if (axis == 0) return {q.y(), q.z()};
  if (axis == 1) return {q.x(), q.z()};
  return {q.x(), q.y()};
}

std::optional<Hit> intersect_box(const Box& box, const Ray& ray, double lo, double hi) {
  const double c = std::cos(box.yaw_rad);
  const double s = std::sin(box.yaw_rad);
  const Vector3d o = yaw_rotate(ray.origin - box.center, c, -s);
  const Vector3d d = yaw_rotate(ray.direction, c, -s);
  const Vector3d& h = box.half_extent;
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  int near_axis = -1;
  int far_axis = -1;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (std::abs(o[k]) > h[k]) return std::nullopt;  // parallel to and outside this slab
      continue;
    }
    const double ta = (-h[k] - o[k]) / d[k];
    const double tb = (h[k] - o[k]) / d[k];
    if (std::min(ta, tb) > t_near) {
      t_near = std::min(ta, tb);
      near_axis = k;
    }
    if (std::max(ta, tb) < t_far) {
      t_far = std::max(ta, tb);
      far_axis = k;
    }
  }
  if (t_near > t_far) return std::nullopt;
  const bool entry = near_axis >= 0 && in_window(t_near, lo, hi);
  if (!entry && !in_window(t_far, lo, hi)) return std::nullopt;
  const double t = entry ? t_near : t_far;
  const int axis = entry ? near_axis : far_axis;
  Vector3d n_local = Vector3d::Zero();
  n_local[axis] = d[axis] > 0.0 ? -1.0 : 1.0;
  const Vector2d uv = box_face_uv(o + t * d, h, axis);
  return make_hit(t, yaw_rotate(n_local, c, s), ray.direction, uv);
}

// Nearest side-wall hit of a vertical cylinder, in coordinates relative to the
// base centre; infinity when none lies in [lo, hi] and within the height.
double cylinder_side(const Cylinder& cyl, const Vector3d& o, const Vector3d& d, double lo,
                     double hi) {
  const double a = d.x() * d.x() + d.y() * d.y();
  const double b = o.x() * d.x() + o.y() * d.y();
  const double offset = o.x() * d.y() - o.y() * d.x();  // a · (perpendicular distance)²
  const double disc = a * cyl.radius * cyl.radius - offset * offset;
  if (a == 0.0 || disc <= 0.0) return std::numeric_limits<double>::infinity();
  const double root = std::sqrt(disc);
  for (const double t : {(-b - root) / a, (-b + root) / a}) {
    const double z = o.z() + t * d.z();
    if (in_window(t, lo, hi) && z >= 0.0 && z <= cyl.height) return t;
  }
  return std::numeric_limits<double>::infinity();
}

// Nearest cap hit (bottom or top disc), relative to the base centre.
double cylinder_caps(const Cylinder& cyl, const Vector3d& o, const Vector3d& d, double lo,
                     double hi) {
  double best = std::numeric_limits<double>::infinity();
  if (d.z() == 0.0) return best;
  for (const double z : {0.0, cyl.height}) {
    const double t = (z - o.z()) / d.z();
    const Vector3d p = o + t * d;
    const bool inside = p.x() * p.x() + p.y() * p.y() <= cyl.radius * cyl.radius;
    if (in_window(t, lo, hi) && inside && t < best) best = t;
  }
  return best;
}

// Side uv: (arc length from azimuth 0 counter-clockwise from +x, height).
// Cap uv (not specified by the header): (x, y) offsets from the axis [m].
std::optional<Hit> intersect_cylinder(const Cylinder& cyl, const Ray& ray, double lo, double hi) {
  const Vector3d o = ray.origin - cyl.base_center;
  const Vector3d& d = ray.direction;
  const double t_side = cylinder_side(cyl, o, d, lo, hi);
  const double t_cap = cylinder_caps(cyl, o, d, lo, std::min(hi, t_side));
  if (std::isinf(t_side) && std::isinf(t_cap)) return std::nullopt;
  const bool cap = t_cap <= t_side;
  const double t = cap ? t_cap : t_side;
  const Vector3d p = o + t * d;
  if (cap) return make_hit(t, Vector3d::UnitZ(), d, Vector2d(p.x(), p.y()));
  double azimuth = std::atan2(p.y(), p.x());
  if (azimuth < 0.0) azimuth += 2.0 * std::numbers::pi;
  const Vector3d n = Vector3d(p.x(), p.y(), 0.0).normalized();
  return make_hit(t, n, d, Vector2d(azimuth * cyl.radius, p.z()));
}

// uv: (longitude in (−π, π] from +x, latitude in [−π/2, π/2]) × radius.
std::optional<Hit> intersect_sphere(const Sphere& sphere, const Ray& ray, double lo, double hi) {
  const Vector3d oc = ray.origin - sphere.center;
  const double b = oc.dot(ray.direction);
  const double disc = sphere.radius * sphere.radius - (oc - b * ray.direction).squaredNorm();
  if (disc <= 0.0) return std::nullopt;
  const double root = std::sqrt(disc);
  double t = -b - root;
  if (!in_window(t, lo, hi)) t = -b + root;
  if (!in_window(t, lo, hi)) return std::nullopt;
  const Vector3d p = oc + t * ray.direction;
  const double longitude = std::atan2(p.y(), p.x());
  const double latitude = std::asin(std::clamp(p.z() / sphere.radius, -1.0, 1.0));
  const Vector2d uv(longitude * sphere.radius, latitude * sphere.radius);
  return make_hit(t, p.normalized(), ray.direction, uv);
}

std::optional<Hit> intersect_triangle(const Triangle& tri, const Ray& ray, double lo, double hi) {
  const Vector3d e1 = tri.b - tri.a;
  const Vector3d e2 = tri.c - tri.a;
  const Vector3d p = ray.direction.cross(e2);
  const double det = e1.dot(p);  // = −dot(direction, e1 × e2)
  const double limit = kParallelCosine * kParallelCosine * e1.squaredNorm() * e2.squaredNorm();
  if (det * det <= limit) return std::nullopt;
  const double inv_det = 1.0 / det;
  const Vector3d s = ray.origin - tri.a;
  const double u = s.dot(p) * inv_det;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const Vector3d q = s.cross(e1);
  const double v = ray.direction.dot(q) * inv_det;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double t = e2.dot(q) * inv_det;
  if (!in_window(t, lo, hi)) return std::nullopt;
  const Vector3d hit_point = ray.origin + t * ray.direction;
  return make_hit(t, e1.cross(e2).normalized(), ray.direction, hit_point.head<2>());
}

}  // namespace

std::optional<Hit> intersect_shape(const Shape& shape, const Ray& ray, double min_distance_m,
                                   double max_distance_m) {
  return std::visit(
      [&](const auto& s) -> std::optional<Hit> {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Quad>) {
          return intersect_quad(s, ray, min_distance_m, max_distance_m);
        } else if constexpr (std::is_same_v<T, Box>) {
          return intersect_box(s, ray, min_distance_m, max_distance_m);
        } else if constexpr (std::is_same_v<T, Cylinder>) {
          return intersect_cylinder(s, ray, min_distance_m, max_distance_m);
        } else if constexpr (std::is_same_v<T, Sphere>) {
          return intersect_sphere(s, ray, min_distance_m, max_distance_m);
        } else {
          return intersect_triangle(s, ray, min_distance_m, max_distance_m);
        }
      },
      shape);
}

Eigen::AlignedBox3d shape_bounds(const Shape& shape) {
  struct Bounds {
    Eigen::AlignedBox3d operator()(const Quad& q) const {
      Eigen::AlignedBox3d box(q.origin);
      box.extend(q.origin + q.edge_u).extend(q.origin + q.edge_v);
      return box.extend(q.origin + q.edge_u + q.edge_v);
    }
    Eigen::AlignedBox3d operator()(const Box& b) const {
      // Half-widths of the yawed footprint along world x and y.
      const double c = std::abs(std::cos(b.yaw_rad));
      const double s = std::abs(std::sin(b.yaw_rad));
      const Vector3d reach(c * b.half_extent.x() + s * b.half_extent.y(),
                           s * b.half_extent.x() + c * b.half_extent.y(), b.half_extent.z());
      return {b.center - reach, b.center + reach};
    }
    Eigen::AlignedBox3d operator()(const Cylinder& c) const {
      const Vector3d reach(c.radius, c.radius, 0.0);
      return {c.base_center - reach, c.base_center + reach + Vector3d(0.0, 0.0, c.height)};
    }
    Eigen::AlignedBox3d operator()(const Sphere& s) const {
      return {s.center.array() - s.radius, s.center.array() + s.radius};
    }
    Eigen::AlignedBox3d operator()(const Triangle& t) const {
      Eigen::AlignedBox3d box(t.a);
      return box.extend(t.b).extend(t.c);
    }
  };
  return std::visit(Bounds{}, shape);
}

}  // namespace scanbench::acquisition::sim
