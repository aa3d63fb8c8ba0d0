// Body-level line query (Table I case C, eq. 21): frames, pushing vs pulling point over several
// shapes, misses, degenerate inputs, no allocation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "extwrench/geometry/ray.hpp"
#include "extwrench/io/mesh.hpp"
#include "geometry/mesh_files.hpp"
#include "geometry/shape_checks.hpp"
#include "support/alloc_counter.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

constexpr double kPointTolerance = 1e-9;

Vector3 random_unit(SeededRng& rng) {
  for (;;) {
    const Vector3 v = rng.uniform_vector3(-1.0, 1.0);
    if (v.norm() > 0.1 && v.norm() <= 1.0) return v.normalized();
  }
}

Pose random_pose(SeededRng& rng) {
  return Pose::from_xyz_rpy(rng.uniform_vector3(-1.0, 1.0), rng.uniform_vector3(-3.0, 3.0));
}

/// Body 0: no shape. Body 1: a box at x = −0.5 and a sphere at x = +0.5 (body frame).
GeometryModel two_shape_model() {
  GeometryModel g;
  CollisionShape box = test::make_box(Vector3(0.2, 0.2, 0.2));
  box.body = 1;
  box.placement = Pose::from_xyz_rpy(Vector3(-0.5, 0.0, 0.0), Vector3::Zero());
  CollisionShape sphere = test::make_sphere(0.1);
  sphere.body = 1;
  sphere.placement = Pose::from_xyz_rpy(Vector3(0.5, 0.0, 0.0), Vector3::Zero());
  g.shapes = {box, sphere};
  g.body_shapes = {{}, {0, 1}};
  return g;
}

TEST(RayBody, PushingPointIsTheFirstCrossingOverAllShapesAndPullingTheLast) {
  const GeometryModel g = two_shape_model();
  SeededRng rng(31);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose X_WB = random_pose(rng);
    // Along +x through both shapes: enters the box at x = −0.6, leaves the sphere at x = 0.6.
    const double start = rng.uniform(-2.0, 2.0);
    const Vector3 p_B(start, 0.01, -0.02);
    const SurfacePointResult r =
        intersect_line_with_body(g, 1, X_WB, X_WB.act(p_B), X_WB.rotation * Vector3::UnitX());
    ASSERT_TRUE(r.hit);
    EXPECT_EQ(r.num_hits, 4);
    EXPECT_EQ(r.entry.shape, 0);
    EXPECT_EQ(r.exit.shape, 1);
    EXPECT_NEAR(r.entry.lambda, -0.6 - start, 1e-12);
    const double x_exit = std::sqrt(0.01 - 0.01 * 0.01 - 0.02 * 0.02) + 0.5;
    EXPECT_NEAR(r.exit.lambda, x_exit - start, 1e-12);
    EXPECT_LT((r.entry.point_W - X_WB.act(Vector3(-0.6, 0.01, -0.02))).norm(), 1e-12);
    EXPECT_LT((r.entry.normal_W - X_WB.rotation * -Vector3::UnitX()).norm(), 1e-12);
    EXPECT_EQ(r.distance, 0.0);
    EXPECT_EQ(r.closest_point_W, r.entry.point_W);
    EXPECT_EQ(r.shape, 0);
    // Reversing the direction swaps pushing and pulling.
    const SurfacePointResult back =
        intersect_line_with_body(g, 1, X_WB, X_WB.act(p_B), X_WB.rotation * -Vector3::UnitX());
    EXPECT_EQ(back.entry.shape, 1);
    EXPECT_LT((back.entry.point_W - r.exit.point_W).norm(), 1e-12);
    EXPECT_LT((back.exit.point_W - r.entry.point_W).norm(), 1e-12);
  }
}

TEST(RayBody, RecoversSurfacePointsOfPosedShapesInTheWorldFrame) {
  SeededRng rng(32);
  const std::vector<CollisionShape> shapes = {
      test::make_sphere(0.3), test::make_box(Vector3(0.4, 0.2, 0.7)),
      test::make_cylinder(0.15, 0.6), test::make_capsule(0.1, 0.5)};
  for (const CollisionShape& prototype : shapes) {
    int tested = 0;
    for (int trial = 0; trial < 300; ++trial) {
      GeometryModel g;
      g.shapes = {prototype};
      g.shapes[0].placement = random_pose(rng);
      g.body_shapes = {{0}};
      const Pose X_WB = random_pose(rng);
      const Pose X_WS = X_WB * g.shapes[0].placement;
      const Vector3 q_S = test::surface_point_towards(prototype, random_unit(rng));
      Vector3 n_S;
      if (!test::numerical_normal(prototype, q_S, n_S)) continue;
      const Vector3 u_W = random_unit(rng);
      if ((X_WS.rotation * n_S).dot(u_W) > -0.05) continue;
      const double s = rng.uniform(-1.0, 1.0);
      const Vector3 q_W = X_WS.act(q_S);
      // An unnormalised direction: λ is still in metres along the unit direction.
      const SurfacePointResult r = intersect_line_with_body(g, 0, X_WB, q_W + s * u_W, 3.7 * u_W);
      ASSERT_TRUE(r.hit);
      EXPECT_EQ(r.num_hits, 2);
      EXPECT_LT((r.entry.point_W - q_W).norm(), kPointTolerance);
      EXPECT_NEAR(r.entry.lambda, -s, kPointTolerance);
      EXPECT_LT((r.entry.normal_W - X_WS.rotation * n_S).norm(), 1e-5);
      EXPECT_NEAR(test::implicit(prototype, X_WS.inverse().act(r.exit.point_W)), 0.0, 1e-12);
      EXPECT_GT(r.exit.lambda, r.entry.lambda);
      ++tested;
    }
    EXPECT_GT(tested, 50);
  }
}

TEST(RayBody, MissReportsTheNearestShapeAndItsClosestPoint) {
  const GeometryModel g = two_shape_model();
  const Pose X_WB = Pose::from_xyz_rpy(Vector3(0.3, -0.2, 1.0), Vector3(0.1, -0.7, 2.0));
  // In the body frame: a line along y at z = 0.3 above the sphere (top at z = 0.1) and the box
  // (top at z = 0.1), shifted towards the sphere: nearest is the sphere at distance 0.2.
  const Vector3 p_B(0.5, -1.0, 0.3);
  const SurfacePointResult r =
      intersect_line_with_body(g, 1, X_WB, X_WB.act(p_B), X_WB.rotation * Vector3::UnitY());
  EXPECT_FALSE(r.hit);
  EXPECT_EQ(r.num_hits, 0);
  EXPECT_EQ(r.shape, 1);
  EXPECT_NEAR(r.distance, 0.2, 1e-12);
  EXPECT_LT((r.closest_point_W - X_WB.act(Vector3(0.5, 0.0, 0.1))).norm(), 1e-12);
  EXPECT_NEAR(r.closest_lambda, 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(r.entry.lambda));
  EXPECT_TRUE(std::isnan(r.exit.point_W.x()));
  EXPECT_EQ(r.entry.shape, -1);
}

TEST(RayBody, HitOnlyQueryAgreesOnHitsAndSkipsTheNearestPointOnMisses) {
  const GeometryModel g = two_shape_model();
  SeededRng rng(33);
  int hits = 0, misses = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Pose X_WB = random_pose(rng);
    // Even trials start inside the box or the sphere (a hit whatever the direction), odd
    // trials anywhere around them (mostly misses).
    const Vector3 centre_B((trial % 4 == 0) ? -0.5 : 0.5, 0.0, 0.0);
    const Vector3 p_B = trial % 2 == 0 ? Vector3(centre_B + rng.uniform_vector3(-0.05, 0.05))
                                       : Vector3(rng.uniform_vector3(-0.8, 0.8));
    const Vector3 p_W = X_WB.act(p_B);
    const Vector3 u_W = random_unit(rng);
    const SurfacePointResult full = intersect_line_with_body(g, 1, X_WB, p_W, u_W);
    const SurfacePointResult only =
        intersect_line_with_body(g, 1, X_WB, p_W, u_W, OnMiss::kNothing);
    ASSERT_EQ(only.hit, full.hit);
    if (full.hit) {
      ++hits;
      EXPECT_EQ(only.num_hits, full.num_hits);
      EXPECT_EQ(only.entry.point_W, full.entry.point_W);
      EXPECT_EQ(only.exit.point_W, full.exit.point_W);
      EXPECT_EQ(only.entry.shape, full.entry.shape);
      EXPECT_EQ(only.distance, 0.0);
    } else {
      ++misses;
      EXPECT_TRUE(std::isfinite(full.distance));
      EXPECT_EQ(only.distance, std::numeric_limits<double>::infinity());
      EXPECT_TRUE(std::isnan(only.closest_point_W.x()));
      EXPECT_EQ(only.shape, -1);
    }
  }
  EXPECT_GE(hits, 200);
  EXPECT_GT(misses, 100);
}

TEST(RayBody, DegenerateInputsGiveNoHit) {
  const GeometryModel g = two_shape_model();
  const Pose X = Pose::identity();
  const Vector3 p(-2.0, 0.0, 0.0);
  // Zero or non-finite direction: no line at all.
  for (const Vector3& d : {Vector3(Vector3::Zero()), Vector3(NAN, 0.0, 0.0),
                           Vector3(std::numeric_limits<double>::infinity(), 0.0, 0.0)}) {
    const SurfacePointResult r = intersect_line_with_body(g, 1, X, p, d);
    EXPECT_FALSE(r.hit);
    EXPECT_TRUE(std::isnan(r.distance));
    EXPECT_EQ(r.shape, -1);
  }
  EXPECT_FALSE(intersect_line_with_body(g, 1, X, Vector3(NAN, 0.0, 0.0), Vector3::UnitX()).hit);
  // A body without shapes, or out of range: no hit, infinitely far.
  for (const int body : {0, -1, 2}) {
    const SurfacePointResult r = intersect_line_with_body(g, body, X, p, Vector3::UnitX());
    EXPECT_FALSE(r.hit);
    EXPECT_EQ(r.distance, std::numeric_limits<double>::infinity());
    EXPECT_EQ(r.shape, -1);
  }
  // A mesh shape whose mesh was not loaded is skipped.
  GeometryModel unloaded;
  CollisionShape mesh;
  mesh.type = ShapeType::kMesh;
  unloaded.shapes = {mesh};
  unloaded.body_shapes = {{0}};
  const SurfacePointResult r = intersect_line_with_body(unloaded, 0, X, p, Vector3::UnitX());
  EXPECT_FALSE(r.hit);
  EXPECT_EQ(r.distance, std::numeric_limits<double>::infinity());
}

TEST(RayBody, MeshEntryNormalFacesThePusherEvenWithInwardWinding) {
  // The box mesh with every triangle reversed (normals inward).
  test::SimpleMesh box = test::box_mesh(Vector3(0.5, 0.25, 0.75));
  for (auto& t : box.triangles) std::swap(t[1], t[2]);
  GeometryModel g;
  CollisionShape s;
  s.type = ShapeType::kMesh;
  s.mesh = make_triangle_mesh(test::vertex_matrix(box), test::triangle_matrix(box), "inward box");
  g.shapes = {s};
  g.body_shapes = {{0}};
  const SurfacePointResult r =
      intersect_line_with_body(g, 0, Pose::identity(), Vector3(-2.0, 0.01, 0.02), Vector3::UnitX());
  ASSERT_TRUE(r.hit);
  EXPECT_LT((r.entry.normal_W + Vector3::UnitX()).norm(), 1e-15);
  EXPECT_LT((r.exit.normal_W - Vector3::UnitX()).norm(), 1e-15);
}

TEST(RayBody, QueriesDoNotAllocateForPrimitivesAndEmbreeMeshes) {
  if (!test::allocation_counting_available()) GTEST_SKIP() << "allocation counting unavailable";
  GeometryModel g = two_shape_model();
  CollisionShape cylinder = test::make_cylinder(0.1, 0.3);
  cylinder.placement = Pose::from_xyz_rpy(Vector3(0.0, 0.4, 0.0), Vector3(0.3, 0.2, 0.1));
  CollisionShape capsule = test::make_capsule(0.05, 0.2);
  capsule.placement = Pose::from_xyz_rpy(Vector3(0.0, -0.4, 0.0), Vector3(-0.3, 0.2, 0.1));
  const test::SimpleMesh sphere = test::icosphere_mesh(0.1, 2);
  CollisionShape mesh;
  mesh.type = ShapeType::kMesh;
  mesh.mesh = make_triangle_mesh(test::vertex_matrix(sphere), test::triangle_matrix(sphere), "ico");
  mesh.placement = Pose::from_xyz_rpy(Vector3(0.0, 0.0, 0.4), Vector3::Zero());
  g.shapes.insert(g.shapes.end(), {cylinder, capsule, mesh});
  g.body_shapes[1] = {0, 1, 2, 3, 4};

  SeededRng rng(33);
  const Pose X_WB = Pose::from_xyz_rpy(Vector3(0.1, 0.2, 0.3), Vector3(0.4, 0.5, 0.6));
  std::vector<Vector3> points, directions;
  for (int i = 0; i < 500; ++i) {
    // Every fourth line through the mesh sphere, so the Embree path is exercised.
    const Vector3 p_B = i % 4 == 0 ? Vector3(rng.uniform_vector3(-0.05, 0.05) + Vector3(0, 0, 0.4))
                                   : rng.uniform_vector3(-0.7, 0.7);
    points.push_back(X_WB.act(p_B));
    directions.push_back(random_unit(rng));
  }
  (void)intersect_line_with_body(g, 1, X_WB, points[0], directions[0]);  // Embree warm-up
  int hits = 0, misses = 0, mesh_hits = 0;
  const test::AllocationCounter counter;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SurfacePointResult r = intersect_line_with_body(g, 1, X_WB, points[i], directions[i]);
    (r.hit ? hits : misses) += 1;
    mesh_hits += r.entry.shape == 4 || r.exit.shape == 4;
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_GT(hits, 50);
  EXPECT_GT(misses, 50);
  EXPECT_GT(mesh_hits, 50);
}

}  // namespace
}  // namespace extwrench
