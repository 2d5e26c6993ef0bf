// Ray casting against the simulated scene: hand-computed hits for every shape,
// the distance window, grazing rays, the BVH against brute force, bookkeeping.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/scene.hpp"

namespace scanbench::acquisition::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTol = 1e-12;

Ray ray(Vector3d origin, Vector3d direction) {
  return {origin, direction.normalized()};
}

std::optional<Hit> cast(const Shape& shape, const Ray& r, double lo = 0.0, double hi = kInf) {
  return intersect_shape(shape, r, lo, hi);
}

void expect_hit(const std::optional<Hit>& hit, double distance, const Vector3d& normal,
                const Vector2d& uv) {
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->distance_m, distance, kTol);
  EXPECT_LT((hit->normal - normal).norm(), kTol) << hit->normal.transpose();
  EXPECT_LT((hit->uv_m - uv).norm(), kTol) << hit->uv_m.transpose();
}

// --- Quad -------------------------------------------------------------------

const Quad kWall{{0, 0, 0}, {2, 0, 0}, {0, 0, 3}};  // 2 m × 3 m in the xz plane

TEST(SimShapes, QuadHitFromBothSides) {
  expect_hit(cast(kWall, ray({0.5, -4, 1.5}, {0, 1, 0})), 4.0, {0, -1, 0}, {0.5, 1.5});
  expect_hit(cast(kWall, ray({1, 5, 2}, {0, -1, 0})), 5.0, {0, 1, 0}, {1.0, 2.0});
  // Oblique: from (0,−1,0) towards (1,0,1) hits at s = 0.5, t = 1/3.
  expect_hit(cast(kWall, ray({0, -1, 0}, {1, 1, 1})), std::sqrt(3.0), {0, -1, 0}, {1.0, 1.0});
}

TEST(SimShapes, QuadMissesOutsideAndParallel) {
  EXPECT_FALSE(cast(kWall, ray({2.5, -4, 1}, {0, 1, 0})));
  EXPECT_FALSE(cast(kWall, ray({1, -4, -0.1}, {0, 1, 0})));
  EXPECT_FALSE(cast(kWall, ray({-1, 0, 1}, {1, 0, 0})));   // in the plane: grazes
  EXPECT_FALSE(cast(kWall, ray({-1, -1, 1}, {1, 0, 0})));  // parallel, off the plane
  EXPECT_FALSE(cast(kWall, ray({1, -4, 1}, {0, -1, 0})));  // wall behind the origin
}

// --- Box --------------------------------------------------------------------

TEST(SimShapes, BoxHitFromOutside) {
  const Box box{{0, 0, 1}, {1, 2, 1}};
  // x face: u along local y, v along z, from the face's low corner.
  expect_hit(cast(box, ray({-5, 0.5, 1.5}, {1, 0, 0})), 4.0, {-1, 0, 0}, {2.5, 1.5});
  // y face: u along x.
  expect_hit(cast(box, ray({0.25, 9, 0.5}, {0, -1, 0})), 7.0, {0, 1, 0}, {1.25, 0.5});
  // Top: x then y.
  expect_hit(cast(box, ray({0.5, -1, 10}, {0, 0, -1})), 8.0, {0, 0, 1}, {1.5, 1.0});
  EXPECT_FALSE(cast(box, ray({-5, 2.5, 1}, {1, 0, 0})));
}

TEST(SimShapes, BoxYawedAboutItsCentre) {
  // Yaw 90°: local +y points along world −x, so the world −x face is local +y.
  const Box box{{0, 0, 0}, {1, 2, 0.5}, kPi / 2};
  // Hit (−2, 0.3, 0.2) is local (0.3, 2, 0.2): u = 0.3 + 1, v = 0.2 + 0.5.
  expect_hit(cast(box, ray({-10, 0.3, 0.2}, {1, 0, 0})), 8.0, {-1, 0, 0}, {1.3, 0.7});
  // World y extent is the local x half extent, 1.
  // Hit (0.5, 1, 0) is local (1, −0.5, 0), on the local +x face.
  expect_hit(cast(box, ray({0.5, 6, 0}, {0, -1, 0})), 5.0, {0, 1, 0}, {1.5, 0.5});
  EXPECT_FALSE(cast(box, ray({-10, 1.2, 0}, {1, 0, 0})));
}

TEST(SimShapes, BoxFromInsideHitsTheExitFace) {
  const Box box{{0, 0, 0}, {1, 1, 1}};
  expect_hit(cast(box, ray({0, 0, 0}, {0, 0, 1})), 1.0, {0, 0, -1}, {1.0, 1.0});
  // A window starting past the entry face also gives the exit face.
  expect_hit(cast(box, ray({-5, 0, 0}, {1, 0, 0}), 4.5), 6.0, {-1, 0, 0}, {1.0, 1.0});
}

TEST(SimShapes, BoxRayInAFacePlaneHitsTheClosedBox) {
  const Box box{{0, 0, 0}, {1, 1, 1}};
  expect_hit(cast(box, ray({-5, 0, 1}, {1, 0, 0})), 4.0, {-1, 0, 0}, {1.0, 2.0});
  EXPECT_FALSE(cast(box, ray({-5, 0, 1.0001}, {1, 0, 0})));
}

// --- Cylinder ---------------------------------------------------------------

const Cylinder kPost{{1, 2, 0}, 0.5, 3.0};

TEST(SimShapes, CylinderSideAndCaps) {
  // Azimuth of the hit (0, −0.5) is 3π/2: arc length 3π/2 · 0.5.
  expect_hit(cast(kPost, ray({1, -3, 1}, {0, 1, 0})), 4.5, {0, -1, 0}, {0.75 * kPi, 1.0});
  expect_hit(cast(kPost, ray({5, 2, 2}, {-1, 0, 0})), 3.5, {1, 0, 0}, {0.0, 2.0});
  // Caps: uv = offset from the axis.
  expect_hit(cast(kPost, ray({1.2, 2, 10}, {0, 0, -1})), 7.0, {0, 0, 1}, {0.2, 0.0});
  expect_hit(cast(kPost, ray({1, 1.9, -1}, {0, 0, 1})), 1.0, {0, 0, -1}, {0.0, -0.1});
}

TEST(SimShapes, CylinderFromInside) {
  expect_hit(cast(kPost, ray({1, 2, 1}, {0, 0, -1})), 1.0, {0, 0, 1}, {0.0, 0.0});
  expect_hit(cast(kPost, ray({1, 2, 1}, {1, 0, 0})), 0.5, {-1, 0, 0}, {0.0, 1.0});
}

TEST(SimShapes, CylinderMisses) {
  EXPECT_FALSE(cast(kPost, ray({1, -3, 3.5}, {0, 1, 0})));    // passes over the top
  EXPECT_FALSE(cast(kPost, ray({1.6, 2, 10}, {0, 0, -1})));   // vertical, outside the radius
  EXPECT_FALSE(cast(kPost, ray({1.5, -3, 1}, {0, 1, 0})));    // tangent to the side
  EXPECT_FALSE(cast(kPost, ray({1, 2, 3}, {1, 0, 0}), 0.6));  // window past the wall
}

// --- Sphere -----------------------------------------------------------------

const Sphere kBall{{1, 1, 1}, 2.0};

TEST(SimShapes, SphereHitsWithLongitudeLatitudeUv) {
  expect_hit(cast(kBall, ray({1, 1, -9}, {0, 0, 1})), 8.0, {0, 0, -1}, {0.0, -kPi});
  expect_hit(cast(kBall, ray({10, 1, 1}, {-1, 0, 0})), 7.0, {1, 0, 0}, {0.0, 0.0});
  expect_hit(cast(kBall, ray({1, 10, 1}, {0, -1, 0})), 7.0, {0, 1, 0}, {kPi, 0.0});
  // Oblique, through the centre: hit at local (√2, −√2, 0), longitude −π/4.
  const double d = 10.0 * std::sqrt(2.0) - 2.0;
  const Vector3d n(std::sqrt(0.5), -std::sqrt(0.5), 0);
  expect_hit(cast(kBall, ray({11, -9, 1}, {-1, 1, 0})), d, n, {-kPi / 2, 0.0});
}

TEST(SimShapes, SphereFromInsideAndTangent) {
  expect_hit(cast(kBall, ray({1, 1, 1}, {1, 0, 0})), 2.0, {-1, 0, 0}, {0.0, 0.0});
  EXPECT_FALSE(cast(kBall, ray({-9, 3, 1}, {1, 0, 0})));  // tangent at (1, 3, 1)
  EXPECT_FALSE(cast(kBall, ray({-9, 3.001, 1}, {1, 0, 0})));
  EXPECT_FALSE(cast(kBall, ray({-9, 1, 1}, {-1, 0, 0})));  // behind
}

// --- Triangle ---------------------------------------------------------------

const Triangle kTile{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};

TEST(SimShapes, TriangleTwoSidedWithWorldXyUv) {
  expect_hit(cast(kTile, ray({1, 1, 5}, {0, 0, -1})), 5.0, {0, 0, 1}, {1.0, 1.0});
  expect_hit(cast(kTile, ray({1, 1, -2}, {0, 0, 1})), 2.0, {0, 0, -1}, {1.0, 1.0});
  expect_hit(cast(kTile, ray({0, 0, 3}, {1, 1, -2})), 1.5 * std::sqrt(6.0), {0, 0, 1}, {1.5, 1.5});
  const Triangle tilted{{10, 0, 0}, {10, 2, 0}, {10, 0, 2}};  // in the plane x = 10
  expect_hit(cast(tilted, ray({0, 0.5, 0.5}, {1, 0, 0})), 10.0, {-1, 0, 0}, {10.0, 0.5});
}

TEST(SimShapes, TriangleMissesOutsideAndParallel) {
  EXPECT_FALSE(cast(kTile, ray({3, 3, 5}, {0, 0, -1})));
  EXPECT_FALSE(cast(kTile, ray({-0.1, 1, 5}, {0, 0, -1})));
  EXPECT_FALSE(cast(kTile, ray({-1, 1, 0}, {1, 0, 0})));  // in the plane
  EXPECT_FALSE(cast(kTile, ray({-1, 1, 1}, {1, 0, 0})));  // parallel above
}

// --- Distance window and normals ---------------------------------------------

TEST(SimShapes, DistanceWindowIsClosedAndRespected) {
  const Ray r = ray({1, 1, -9}, {0, 0, 1});                            // enters at 8, leaves at 12
  expect_hit(cast(kBall, r, 0.0, 8.0), 8.0, {0, 0, -1}, {0.0, -kPi});  // max is inclusive
  EXPECT_FALSE(cast(kBall, r, 0.0, 7.999));
  expect_hit(cast(kBall, r, 8.0, 20.0), 8.0, {0, 0, -1}, {0.0, -kPi});  // min is inclusive
  expect_hit(cast(kBall, r, 8.5, 20.0), 12.0, {0, 0, -1}, {0.0, kPi});  // exit, from inside
  EXPECT_FALSE(cast(kBall, r, 12.5, 20.0));
  EXPECT_FALSE(cast(kWall, ray({0.5, -4, 1.5}, {0, 1, 0}), 4.5, 9.0));
  EXPECT_FALSE(cast(kTile, ray({1, 1, 5}, {0, 0, -1}), 0.0, 4.0));
  EXPECT_FALSE(cast(kPost, ray({1, -3, 1}, {0, 1, 0}), 0.0, 4.0));
}

std::vector<Shape> sample_shapes() {
  return {kWall, Box{{0.5, 0.5, 0.5}, {1, 0.5, 1.5}, 0.7}, kPost, kBall, kTile};
}

TEST(SimShapes, NormalsAreUnitAndFaceTheOrigin) {
  Random random(7);
  int hits = 0;
  for (const Shape& shape : sample_shapes()) {
    for (int i = 0; i < 2000; ++i) {
      const Vector3d origin(random.uniform(-4, 5), random.uniform(-4, 5), random.uniform(-4, 5));
      const Vector3d target(random.uniform(-1, 3), random.uniform(-1, 3), random.uniform(-1, 3));
      const auto hit = cast(shape, ray(origin, target - origin));
      if (!hit) continue;
      ++hits;
      EXPECT_NEAR(hit->normal.norm(), 1.0, 1e-12);
      EXPECT_LT(hit->normal.dot((target - origin).normalized()), 0.0);
      EXPECT_GE(hit->distance_m, 0.0);
    }
  }
  EXPECT_GT(hits, 1000);
}

TEST(SimShapes, BoundsEncloseTheShapes) {
  const auto yawed = shape_bounds(Box{{0, 0, 0}, {1, 1, 1}, kPi / 4});
  EXPECT_NEAR(yawed.max().x(), std::sqrt(2.0), kTol);
  EXPECT_NEAR(yawed.min().y(), -std::sqrt(2.0), kTol);
  EXPECT_EQ(yawed.max().z(), 1.0);
  const auto post = shape_bounds(kPost);
  EXPECT_TRUE(post.min().isApprox(Vector3d(0.5, 1.5, 0.0)));
  EXPECT_TRUE(post.max().isApprox(Vector3d(1.5, 2.5, 3.0)));
  EXPECT_TRUE(shape_bounds(kBall).max().isApprox(Vector3d(3, 3, 3)));
  EXPECT_TRUE(shape_bounds(kWall).max().isApprox(Vector3d(2, 0, 3)));
  EXPECT_TRUE(shape_bounds(kTile).max().isApprox(Vector3d(4, 4, 0)));
}

// --- Scene ------------------------------------------------------------------

TEST(SimScene, IdsAndHierarchy) {
  Scene scene;
  EXPECT_EQ(scene.add_object("campus", 0, "site"), 1);
  EXPECT_EQ(scene.add_object("library", 1, "building"), 2);
  EXPECT_EQ(scene.add_object("north wall", 2, "wall"), 3);
  EXPECT_EQ(scene.add_object("oak", 1, "tree"), 4);
  EXPECT_EQ(scene.add_material({.name = "brick"}), 0);
  EXPECT_EQ(scene.add_material({.name = "bark"}), 1);
  EXPECT_EQ(
      scene.add_image(
          {.rows = 1, .columns = 2, .rgb = {Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones()}}),
      0);
  ASSERT_EQ(scene.objects().size(), 4u);
  EXPECT_EQ(scene.object(3).name, "north wall");
  EXPECT_EQ(scene.object(3).parent, 2);
  EXPECT_EQ(scene.object(3).kind, "wall");
  EXPECT_EQ(scene.object(1).parent, 0);
  EXPECT_EQ(scene.object(4).id, 4);
  EXPECT_THROW(scene.object(5), std::out_of_range);
  EXPECT_EQ(scene.materials()[1].name, "bark");
  EXPECT_EQ(scene.images().size(), 1u);
}

TEST(SimScene, NearestPrimitiveGivesObjectAndMaterial) {
  Scene scene;
  const ObjectId site = scene.add_object("site", 0, "site");
  const ObjectId near = scene.add_object("near", site, "wall");
  const ObjectId far = scene.add_object("far", site, "wall");
  scene.add_material({.name = "a"});
  const MaterialId paint = scene.add_material({.name = "b"});
  scene.add(Quad{{-1, 10, -1}, {2, 0, 0}, {0, 0, 2}}, far, 0);
  scene.add(Sphere{{0, 5, 0}, 0.5}, near, paint);
  scene.build();
  const auto hit = scene.intersect(ray({0, 0, 0}, {0, 1, 0}), 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->distance_m, 4.5, kTol);
  EXPECT_EQ(hit->object, near);
  EXPECT_EQ(hit->material, paint);
  const auto behind = scene.intersect(ray({0, 0, 0}, {0, 1, 0}), 6.0, 100.0);
  ASSERT_TRUE(behind);
  EXPECT_EQ(behind->object, far);
  EXPECT_FALSE(scene.intersect(ray({0, 0, 0}, {0, 1, 0}), 0.0, 4.0));
  EXPECT_FALSE(scene.intersect(ray({0, 0, 0}, {0, -1, 0}), 0.0, 100.0));
  const auto box = scene.bounds();
  EXPECT_TRUE(box.min().isApprox(Vector3d(-1, 4.5, -1)));
  EXPECT_TRUE(box.max().isApprox(Vector3d(1, 10, 1)));
}

TEST(SimScene, EmptySceneHasNoHits) {
  Scene scene;
  scene.build();
  EXPECT_FALSE(scene.intersect(ray({0, 0, 0}, {1, 0, 0}), 0.0, kInf));
  EXPECT_TRUE(scene.bounds().isEmpty());
}

TEST(SimScene, AxisAlignedRayInABoundingPlane) {
  // The ray lies in the plane z = 1 of the box's bounds: 0 · ∞ in the slab test.
  Scene scene;
  scene.add_object("site", 0, "site");
  scene.add_material({});
  for (int i = 0; i < 20; ++i) scene.add(Box{{5.0 + 3 * i, 0, 0.5}, {1, 1, 0.5}}, 1, 0);
  scene.build();
  const auto hit = scene.intersect(ray({0, 0, 1}, {1, 0, 0}), 0.0, kInf);
  ASSERT_TRUE(hit);
  EXPECT_DOUBLE_EQ(hit->distance_m, 4.0);
  EXPECT_FALSE(scene.intersect(ray({0, 0, 1.5}, {1, 0, 0}), 0.0, kInf));
  // Last box spans x ∈ [61, 63]; a negative zero component must behave like +0.
  const auto back = scene.intersect(ray({100, 0, 1}, {-1, -0.0, 0}), 0.0, kInf);
  ASSERT_TRUE(back);
  EXPECT_DOUBLE_EQ(back->distance_m, 37.0);
  EXPECT_FALSE(scene.intersect(ray({0, 0, 1}, {-1, -0.0, 0}), 0.0, kInf));
}

#ifndef NDEBUG
// Programmer errors are assertions, so these only run in builds with asserts.
TEST(SimSceneDeathTest, AddAssertsOnDegenerateShapesAndUnknownIds) {
  Scene scene;
  scene.add_object("site", 0, "site");
  scene.add_material({});
  EXPECT_DEATH(scene.add(Quad{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, 1, 0), "degenerate");
  EXPECT_DEATH(scene.add(Triangle{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, 1, 0), "degenerate");
  EXPECT_DEATH(scene.add(Sphere{{0, 0, 0}, 0.0}, 1, 0), "degenerate");
  EXPECT_DEATH(scene.add(Cylinder{{0, 0, 0}, 1.0, -1.0}, 1, 0), "degenerate");
  EXPECT_DEATH(scene.add(Box{{0, 0, 0}, {1, 0, 1}}, 1, 0), "degenerate");
  EXPECT_DEATH(scene.add(Sphere{{0, 0, 0}, 1.0}, 2, 0), "unknown object");
  EXPECT_DEATH(scene.add(Sphere{{0, 0, 0}, 1.0}, 1, 1), "unknown material");
  EXPECT_DEATH(scene.add_object("orphan", 7, "wall"), "parent");
  EXPECT_DEATH(scene.intersect(ray({0, 0, 0}, {1, 0, 0}), 0.0, 1.0), "before build");
  scene.build();
  EXPECT_DEATH(scene.add(Sphere{{0, 0, 0}, 1.0}, 1, 0), "after build");
}
#endif

Vector3d random_point(Random& random, double half) {
  return {random.uniform(-half, half), random.uniform(-half, half), random.uniform(-half, half)};
}

Vector3d random_direction(Random& random) {
  for (;;) {
    const Vector3d d(random.normal(), random.normal(), random.normal());
    if (d.norm() > 1e-6) return d.normalized();
  }
}

Shape random_shape(Random& random) {
  const Vector3d p = random_point(random, 10.0);
  const double size = random.uniform(0.2, 2.5);
  switch (random.integer(0, 4)) {
    case 0:
      return Quad{p, random_direction(random) * size, random_direction(random) * size};
    case 1:
      return Box{p, Vector3d(size, random.uniform(0.1, 2), random.uniform(0.1, 2)),
                 random.uniform(-kPi, kPi)};
    case 2:
      return Cylinder{p, size / 3, random.uniform(0.5, 4)};
    case 3:
      return Sphere{p, size / 2};
    default:
      return Triangle{p, p + random_direction(random) * size, p + random_direction(random) * size};
  }
}

// The nearest hit over every primitive, the definition the BVH must reproduce.
std::optional<Hit> brute_force(const Scene& scene, const Ray& r, double lo, double hi) {
  std::optional<Hit> best;
  for (const Primitive& primitive : scene.primitives()) {
    const auto hit = intersect_shape(primitive.shape, r, lo, hi);
    if (hit && (!best || hit->distance_m < best->distance_m)) {
      best = hit;
      best->object = primitive.object;
      best->material = primitive.material;
    }
  }
  return best;
}

TEST(SimScene, BvhMatchesBruteForce) {
  Random random(20240611);
  Scene scene;
  const ObjectId site = scene.add_object("site", 0, "site");
  scene.add_material({});
  for (int i = 0; i < 500; ++i) {
    // One object per primitive, so the object id tells which primitive was hit.
    scene.add(random_shape(random), scene.add_object("p", site, "thing"), 0);
  }
  scene.build();
  ASSERT_EQ(scene.primitives().size(), 500u);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    Vector3d direction = random_direction(random);
    if (i % 5 == 0) direction = Vector3d::Unit(i % 3) * (i % 2 ? 1.0 : -1.0);  // zero components
    const Ray r{random_point(random, 14.0), direction};
    const double lo = i % 3 == 0 ? 0.0 : random.uniform(0.0, 3.0);
    const double hi = i % 4 == 0 ? kInf : random.uniform(5.0, 30.0);
    const auto expected = brute_force(scene, r, lo, hi);
    const auto actual = scene.intersect(r, lo, hi);
    ASSERT_EQ(actual.has_value(), expected.has_value()) << "ray " << i;
    if (!expected) continue;
    ++hits;
    EXPECT_EQ(actual->distance_m, expected->distance_m) << "ray " << i;
    EXPECT_EQ(actual->object, expected->object) << "ray " << i;
    EXPECT_LT((actual->normal - expected->normal).norm(), 1e-12);
    EXPECT_LT(actual->normal.dot(r.direction), 0.0);
  }
  EXPECT_GT(hits, 500);
}

}  // namespace
}  // namespace scanbench::acquisition::sim
