// Scene bookkeeping and its bounding-volume hierarchy.
//
// Construction: binned surface-area heuristic (Wald, "On fast Construction of
// SAH-based Bounding Volume Hierarchies", 2007) with 16 bins on each axis and
// leaves of at most four primitives. Deep subtrees switch to median splits so
// the depth, and with it the traversal stack, stays bounded. primitives_ is
// reordered so that every leaf is a contiguous range, and the two children of
// an inner node are adjacent nodes (first, first + 1).
//
// Traversal: iterative, nearest child first, each box clipped to the current
// best distance. The slab test follows Williams et al., "An Efficient and
// Robust Ray–Box Intersection Algorithm" (2005): per-ray inverse direction and
// sign, with comparisons ordered so that the NaN of 0·∞ (a zero direction
// component with the origin on a slab plane) leaves the interval unchanged.
#include "acquisition/simulation/scene.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

namespace scanbench::acquisition::sim {
namespace {

using Eigen::AlignedBox3d;
using Eigen::Vector3d;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint32_t kMaxLeafSize = 4;
constexpr int kBins = 16;
// Nodes shallower than this split by SAH, deeper ones at the median, which
// halves the count: no tree over < 2³² primitives gets deeper than kSahDepth + 32.
constexpr int kSahDepth = 28;
constexpr int kStackSize = 64;

// Used by assertions only.
[[maybe_unused]] bool is_degenerate(const Shape& shape) {
  struct Check {
    bool operator()(const Quad& q) const { return !(q.edge_u.cross(q.edge_v).norm() > 0.0); }
    bool operator()(const Box& b) const { return !(b.half_extent.minCoeff() > 0.0); }
    bool operator()(const Cylinder& c) const { return !(c.radius > 0.0 && c.height > 0.0); }
    bool operator()(const Sphere& s) const { return !(s.radius > 0.0); }
    bool operator()(const Triangle& t) const {
      return !((t.b - t.a).cross(t.c - t.a).norm() > 0.0);
    }
  };
  // Non-finite coordinates make the bounds, and so the whole BVH, meaningless.
  return std::visit(Check{}, shape) || !shape_bounds(shape).sizes().allFinite();
}

double centroid(const Primitive& primitive, int axis) {
  return shape_bounds(primitive.shape).center()[axis];
}

// Half the surface area: proportional to the chance that a random ray hits the box.
double half_area(const AlignedBox3d& box) {
  if (box.isEmpty()) return 0.0;
  const Vector3d e = box.sizes();
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

// Maps a centroid coordinate to its bin; binning and partitioning must both
// use exactly this expression so that they agree on every primitive.
int bin_of(double c, double lo, double scale) {
  return std::min(kBins - 1, static_cast<int>((c - lo) * scale));
}

struct Plane {
  int axis = -1;  // -1: no plane separates the centroids
  int last_left_bin = 0;
  double cost = kInf;
};

// The cheapest SAH plane between bins over all three axes, considering only
// planes with primitives on both sides.
Plane best_plane(const Primitive* prims, std::uint32_t count, const AlignedBox3d& centroids) {
  struct Bin {
    AlignedBox3d box;
    std::uint32_t count = 0;
  };
  std::array<std::array<Bin, kBins>, 3> bins;
  const Vector3d scale = Vector3d::Constant(kBins).cwiseQuotient(centroids.sizes());
  for (std::uint32_t i = 0; i < count; ++i) {
    const AlignedBox3d box = shape_bounds(prims[i].shape);
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(scale[a])) continue;
      Bin& bin = bins[a][bin_of(box.center()[a], centroids.min()[a], scale[a])];
      bin.box.extend(box);
      ++bin.count;
    }
  }
  Plane best;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(scale[a])) continue;
    std::array<double, kBins> right_cost{};
    AlignedBox3d box;
    std::uint32_t n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      box.extend(bins[a][b].box);
      n += bins[a][b].count;
      right_cost[b - 1] = n == 0 ? kInf : half_area(box) * n;
    }
    box.setEmpty();
    n = 0;
    for (int b = 0; b + 1 < kBins; ++b) {
      box.extend(bins[a][b].box);
      n += bins[a][b].count;
      const double cost = n == 0 ? kInf : half_area(box) * n + right_cost[b];
      if (cost < best.cost) best = {a, b, cost};
    }
  }
  return best;
}

// Reorders [begin, end) into two non-empty halves and returns where the right
// half starts: by the SAH plane when `use_sah` and one exists, else at the
// median along the longest axis of the centroids.
std::uint32_t split(std::vector<Primitive>& prims, std::uint32_t begin, std::uint32_t end,
                    bool use_sah) {
  AlignedBox3d centroids;
  for (std::uint32_t i = begin; i < end; ++i)
    centroids.extend(shape_bounds(prims[i].shape).center());
  const Plane plane = use_sah ? best_plane(&prims[begin], end - begin, centroids) : Plane{};
  if (plane.axis >= 0) {
    const int a = plane.axis;
    const double lo = centroids.min()[a];
    const double scale = kBins / centroids.sizes()[a];
    const auto mid =
        std::partition(prims.begin() + begin, prims.begin() + end, [&](const Primitive& p) {
          return bin_of(centroid(p, a), lo, scale) <= plane.last_left_bin;
        });
    return static_cast<std::uint32_t>(mid - prims.begin());
  }
  int axis = 0;
  centroids.sizes().maxCoeff(&axis);
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(prims.begin() + begin, prims.begin() + mid, prims.begin() + end,
                   [axis](const Primitive& p, const Primitive& q) {
                     return centroid(p, axis) < centroid(q, axis);
                   });
  return mid;
}

// A ray prepared for many slab tests.
struct SlabRay {
  explicit SlabRay(const Ray& ray) : origin(ray.origin) {
    for (int k = 0; k < 3; ++k) {
      inverse[k] = 1.0 / ray.direction[k];  // ±∞ for a (signed) zero component
      negative[k] = std::signbit(ray.direction[k]);
    }
  }

  // Distance at which the ray enters `box` within [lo, hi], or ∞ when it misses.
  double enter(const AlignedBox3d& box, double lo, double hi) const {
    for (int k = 0; k < 3; ++k) {
      const double near = negative[k] ? box.max()[k] : box.min()[k];
      const double far = negative[k] ? box.min()[k] : box.max()[k];
      const double t_near = (near - origin[k]) * inverse[k];
      const double t_far = (far - origin[k]) * inverse[k];
      // Written so that a NaN t_near / t_far is ignored rather than propagated.
      lo = t_near > lo ? t_near : lo;
      hi = t_far < hi ? t_far : hi;
    }
    return lo <= hi ? lo : kInf;
  }

  Vector3d origin;
  Vector3d inverse;
  std::array<bool, 3> negative{};
};

}  // namespace

ObjectId Scene::add_object(std::string name, ObjectId parent, std::string kind) {
  assert((objects_.empty() ? parent == 0 : parent >= 1 && parent <= objects_.size()) &&
         "the first object is the site root (parent 0); later parents must exist");
  assert(objects_.size() < std::numeric_limits<ObjectId>::max() && "too many objects");
  const auto id = static_cast<ObjectId>(objects_.size() + 1);
  objects_.push_back({id, std::move(name), parent, std::move(kind)});
  return id;
}

MaterialId Scene::add_material(Material material) {
  assert(materials_.size() <= std::numeric_limits<MaterialId>::max() && "too many materials");
  materials_.push_back(std::move(material));
  return static_cast<MaterialId>(materials_.size() - 1);
}

int Scene::add_image(TextureImage image) {
  assert(image.rows >= 0 && image.columns >= 0 &&
         image.rgb.size() == static_cast<std::size_t>(image.rows) * image.columns &&
         "image pixel count must be rows × columns");
  images_.push_back(std::move(image));
  return static_cast<int>(images_.size() - 1);
}

void Scene::add(const Shape& shape, ObjectId object, MaterialId material) {
  assert(!built_ && "Scene::add() after build()");
  assert(object >= 1 && object <= objects_.size() && "unknown object id");
  assert(material < materials_.size() && "unknown material id");
  assert(!is_degenerate(shape) && "degenerate or non-finite shape");
  assert(primitives_.size() < std::numeric_limits<std::uint32_t>::max() && "too many primitives");
  primitives_.push_back({shape, object, material});
}

// Appends a leaf node over primitives [begin, end) and returns its index.
std::uint32_t Scene::build_node(std::uint32_t begin, std::uint32_t end) {
  Node node;
  for (std::uint32_t i = begin; i < end; ++i) node.box.extend(shape_bounds(primitives_[i].shape));
  node.first = begin;
  node.count = end - begin;
  nodes_.push_back(node);
  return static_cast<std::uint32_t>(nodes_.size() - 1);
}

void Scene::build() {
  assert(!built_ && "Scene::build() called twice");
  built_ = true;
  nodes_.clear();
  if (primitives_.empty()) return;
  struct Task {
    std::uint32_t node;
    int depth;
  };
  std::vector<Task> pending{{build_node(0, static_cast<std::uint32_t>(primitives_.size())), 0}};
  while (!pending.empty()) {
    const Task task = pending.back();
    pending.pop_back();
    const Node node = nodes_[task.node];  // a copy: build_node() grows nodes_
    if (node.count <= kMaxLeafSize) continue;
    assert(task.depth + 1 < kStackSize && "BVH deeper than the traversal stack");
    const std::uint32_t end = node.first + node.count;
    const std::uint32_t mid = split(primitives_, node.first, end, task.depth < kSahDepth);
    const std::uint32_t left = build_node(node.first, mid);
    build_node(mid, end);
    nodes_[task.node].first = left;
    nodes_[task.node].count = 0;
    pending.push_back({left, task.depth + 1});
    pending.push_back({left + 1, task.depth + 1});
  }
}

std::optional<Hit> Scene::intersect(const Ray& ray, double min_distance_m,
                                    double max_distance_m) const {
  assert(built_ && "Scene::intersect() before build()");
  assert(std::abs(ray.direction.squaredNorm() - 1.0) < 1e-6 && "ray direction must be unit");
  if (nodes_.empty()) return std::nullopt;
  const SlabRay slab(ray);
  struct Pending {
    std::uint32_t node;
    double t;  // entry distance into its box
  };
  std::array<Pending, kStackSize> stack;
  int top = 0;
  std::optional<Hit> best;
  double best_t = max_distance_m;
  if (slab.enter(nodes_[0].box, min_distance_m, best_t) == kInf) return std::nullopt;
  std::uint32_t current = 0;
  for (;;) {
    const Node& node = nodes_[current];
    if (node.count == 0) {
      const double t_left = slab.enter(nodes_[node.first].box, min_distance_m, best_t);
      const double t_right = slab.enter(nodes_[node.first + 1].box, min_distance_m, best_t);
      if (t_left != kInf || t_right != kInf) {
        const bool left_first = t_left <= t_right;
        const double t_far = left_first ? t_right : t_left;
        if (t_far != kInf) stack[top++] = {left_first ? node.first + 1 : node.first, t_far};
        current = left_first ? node.first : node.first + 1;
        continue;
      }
    } else {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const Primitive& primitive = primitives_[i];
        if (auto hit = intersect_shape(primitive.shape, ray, min_distance_m, best_t)) {
          best_t = hit->distance_m;
          best = hit;
          best->object = primitive.object;
          best->material = primitive.material;
        }
      }
    }
    // Resume with the nearest postponed subtree that can still beat best_t.
    do {
      if (top == 0) return best;
      --top;
    } while (stack[top].t > best_t);
    current = stack[top].node;
  }
}

Eigen::AlignedBox3d Scene::bounds() const {
  if (!nodes_.empty()) return nodes_[0].box;
  AlignedBox3d box;
  for (const Primitive& primitive : primitives_) box.extend(shape_bounds(primitive.shape));
  return box;
}

}  // namespace scanbench::acquisition::sim
