// Line intersection and closest points for the analytic primitives, checked against their
// implicit functions, bisection and brute-force sampling (tests/geometry/shape_checks.hpp).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "extwrench/geometry/ray.hpp"
#include "geometry/shape_checks.hpp"
#include "support/alloc_counter.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

// Hits are computed in closed form: only rounding of O(1) quantities remains.
constexpr double kSurfaceTolerance = 1e-12;
// The recovered contact point (docs/geometry.md, Tests: the true surface point to 1e-9 m).
constexpr double kPointTolerance = 1e-9;
// Normals compared with central differences of step 1e-7.
constexpr double kNormalTolerance = 1e-5;

struct NamedShape {
  std::string name;
  CollisionShape shape;
};

std::vector<NamedShape> primitives() {
  return {{"sphere", test::make_sphere(0.3)},
          {"box", test::make_box(Vector3(0.4, 0.2, 0.7))},
          {"cylinder", test::make_cylinder(0.15, 0.6)},
          {"flat_cylinder", test::make_cylinder(0.5, 0.05)},
          {"capsule", test::make_capsule(0.1, 0.5)},
          {"capsule_zero_length", test::make_capsule(0.2, 0.0)}};
}

Vector3 random_unit(SeededRng& rng) {
  for (;;) {
    const Vector3 v = rng.uniform_vector3(-1.0, 1.0);
    if (v.norm() > 0.1 && v.norm() <= 1.0) return v.normalized();
  }
}

Vector3 random_interior_point(SeededRng& rng, const CollisionShape& s) {
  const double r = test::bounding_radius(s);
  for (;;) {
    const Vector3 p = rng.uniform_vector3(-r, r);
    if (test::implicit(s, p) < -1e-6) return p;
  }
}

TEST(RayPrimitives, HitsLieOnTheSurfaceAndOnTheLineWithOutwardNormals) {
  SeededRng rng(11);
  for (const auto& [name, shape] : primitives()) {
    SCOPED_TRACE(name);
    const double r = test::bounding_radius(shape);
    int checked_normals = 0, lines_hitting = 0;
    for (int trial = 0; trial < 2000; ++trial) {
      const Vector3 o = rng.uniform_vector3(-2.0 * r, 2.0 * r);
      const Vector3 u = random_unit(rng);
      std::array<ShapeHit, 8> hits;
      const int n = intersect_line_with_shape(shape, o, u, hits);
      ASSERT_TRUE(n == 0 || n == 2) << n;
      if (n == 2) ++lines_hitting;
      for (int i = 0; i < n; ++i) {
        const ShapeHit& h = hits[static_cast<std::size_t>(i)];
        EXPECT_NEAR(test::implicit(shape, h.point_G), 0.0, kSurfaceTolerance);
        EXPECT_LT((h.point_G - (o + h.lambda * u)).norm(), kSurfaceTolerance);
        EXPECT_NEAR(h.normal_G.norm(), 1.0, 1e-14);
        Vector3 n_fd;
        if (test::numerical_normal(shape, h.point_G, n_fd)) {
          EXPECT_LT((h.normal_G - n_fd).norm(), kNormalTolerance);
          ++checked_normals;
        }
      }
      if (n == 2) {
        EXPECT_LE(hits[0].lambda, hits[1].lambda);
      }
    }
    EXPECT_GT(lines_hitting, 100);
    EXPECT_GT(checked_normals, 200);
  }
}

TEST(RayPrimitives, LinesThroughInteriorPointsEnterBehindAndExitAhead) {
  SeededRng rng(12);
  for (const auto& [name, shape] : primitives()) {
    SCOPED_TRACE(name);
    for (int trial = 0; trial < 2000; ++trial) {
      const Vector3 o = random_interior_point(rng, shape);
      const Vector3 u = random_unit(rng);
      std::array<ShapeHit, 8> hits;
      ASSERT_EQ(intersect_line_with_shape(shape, o, u, hits), 2);
      // The interior point is at λ = 0: entry (pushing) behind it, exit (pulling) ahead.
      EXPECT_LT(hits[0].lambda, 0.0);
      EXPECT_GT(hits[1].lambda, 0.0);
      EXPECT_LE(hits[0].normal_G.dot(u), 1e-12);
      EXPECT_GE(hits[1].normal_G.dot(u), -1e-12);
    }
  }
}

TEST(RayPrimitives, RecoversTheSurfacePointHitFromOutside) {
  SeededRng rng(13);
  for (const auto& [name, shape] : primitives()) {
    SCOPED_TRACE(name);
    int tested = 0;
    for (int trial = 0; trial < 2000; ++trial) {
      const Vector3 q = test::surface_point_towards(shape, random_unit(rng));
      Vector3 n;
      if (!test::numerical_normal(shape, q, n)) continue;  // edges: the inward cone is narrower
      Vector3 u = random_unit(rng);
      if (u.dot(n) > -0.05) continue;  // keep directions pointing into the shape
      // The line is given by any of its points: here one at a random λ from q.
      const double s = rng.uniform(-1.0, 1.0);
      const Vector3 o = q + s * u;
      std::array<ShapeHit, 8> hits;
      ASSERT_EQ(intersect_line_with_shape(shape, o, u, hits), 2);
      EXPECT_LT((hits[0].point_G - q).norm(), kPointTolerance);
      EXPECT_NEAR(hits[0].lambda, -s, kPointTolerance);
      EXPECT_GT(hits[1].lambda, hits[0].lambda);
      ++tested;
    }
    EXPECT_GT(tested, 300);
  }
}

/// Brute force: the line sampled finely, then refined around the best sample.
double sampled_line_distance(const CollisionShape& s, const Vector3& o, const Vector3& u) {
  const double r = test::bounding_radius(s) + o.norm();
  double best_l = 0.0, best = std::numeric_limits<double>::infinity();
  const int n = 4000;
  for (int i = 0; i <= n; ++i) {
    const double l = -r + 2.0 * r * i / n;
    const double d = test::distance_to_solid(s, o + l * u);
    if (d < best) {
      best = d;
      best_l = l;
    }
  }
  double step = 2.0 * r / n;
  for (int k = 0; k < 60; ++k) {
    for (const double l : {best_l - step, best_l + step}) {
      const double d = test::distance_to_solid(s, o + l * u);
      if (d < best) {
        best = d;
        best_l = l;
      }
    }
    step *= 0.7;
  }
  return best;
}

TEST(RayPrimitives, MissesReportTheClosestSurfacePointAsBruteForceSamplingDoes) {
  SeededRng rng(14);
  for (const auto& [name, shape] : primitives()) {
    SCOPED_TRACE(name);
    const double r = test::bounding_radius(shape);
    int misses = 0;
    for (int trial = 0; trial < 150; ++trial) {
      const Vector3 o = rng.uniform_vector3(-2.0 * r, 2.0 * r);
      const Vector3 u = random_unit(rng);
      std::array<ShapeHit, 8> hits;
      if (intersect_line_with_shape(shape, o, u, hits) != 0) continue;
      ++misses;
      const ShapeClosestPoint cp = closest_point_to_line(shape, o, u);
      EXPECT_NEAR(test::implicit(shape, cp.point_G), 0.0, 1e-12);
      // Distance consistent with the returned points, and with brute force.
      EXPECT_NEAR((o + cp.lambda * u - cp.point_G).norm(), cp.distance, 1e-12);
      EXPECT_NEAR(cp.distance, sampled_line_distance(shape, o, u), 1e-9);
      EXPECT_GT(cp.distance, 0.0);
    }
    EXPECT_GT(misses, 30);
  }
}

TEST(RayPrimitives, MissDistancesMatchClosedFormsForOffsetLines) {
  const Vector3 ux = Vector3::UnitX(), uz = Vector3::UnitZ();
  // Sphere r = 0.3, line at distance 0.5 from the centre.
  auto cp = closest_point_to_line(test::make_sphere(0.3), Vector3(-1.0, 0.5, 0.0), ux);
  EXPECT_NEAR(cp.distance, 0.2, 1e-15);
  EXPECT_LT((cp.point_G - Vector3(0.0, 0.3, 0.0)).norm(), 1e-15);
  EXPECT_NEAR(cp.lambda, 1.0, 1e-15);
  // Box 0.4 × 0.2 × 0.7, line parallel to x at y = 0.25: 0.15 from the face y = 0.1.
  cp = closest_point_to_line(test::make_box(Vector3(0.4, 0.2, 0.7)), Vector3(3.0, 0.25, 0.1), ux);
  EXPECT_NEAR(cp.distance, 0.15, 1e-12);
  EXPECT_NEAR(cp.point_G.y(), 0.1, 1e-12);
  // Box, line parallel to z past an edge: distance to the edge (x, y) = (0.2, 0.1).
  cp = closest_point_to_line(test::make_box(Vector3(0.4, 0.2, 0.7)), Vector3(0.5, 0.5, 0.0), uz);
  EXPECT_NEAR(cp.distance, std::hypot(0.3, 0.4), 1e-12);
  // Cylinder r = 0.15, along its axis but offset by 0.4: 0.25.
  cp = closest_point_to_line(test::make_cylinder(0.15, 0.6), Vector3(0.4, 0.0, 5.0), uz);
  EXPECT_NEAR(cp.distance, 0.25, 1e-12);
  // Cylinder, line along x above the top cap (z = 0.3) by 0.2.
  cp = closest_point_to_line(test::make_cylinder(0.15, 0.6), Vector3(0.0, 0.0, 0.5), ux);
  EXPECT_NEAR(cp.distance, 0.2, 1e-12);
  // Capsule r = 0.1, half-length 0.25: line along x through z = 0.6 is 0.6 − 0.25 − 0.1 away.
  cp = closest_point_to_line(test::make_capsule(0.1, 0.5), Vector3(0.0, 0.0, 0.6), ux);
  EXPECT_NEAR(cp.distance, 0.25, 1e-15);
  // Capsule, line parallel to the axis at 0.3: 0.2.
  cp = closest_point_to_line(test::make_capsule(0.1, 0.5), Vector3(0.3, 0.0, 0.0), uz);
  EXPECT_NEAR(cp.distance, 0.2, 1e-15);
}

TEST(RayPrimitives, TangentLineTouchesTheSphereOnce) {
  std::array<ShapeHit, 4> hits;
  const int n = intersect_line_with_shape(test::make_sphere(0.5), Vector3(0.0, 0.5, -3.0),
                                          Vector3::UnitZ(), hits);
  ASSERT_EQ(n, 1);
  EXPECT_LT((hits[0].point_G - Vector3(0.0, 0.5, 0.0)).norm(), 1e-15);
  EXPECT_LT((hits[0].normal_G - Vector3::UnitY()).norm(), 1e-15);
}

TEST(RayPrimitives, LinesParallelToBoxFacesHitTheFacesTheyPoint) {
  const CollisionShape box = test::make_box(Vector3(0.4, 0.2, 0.7));
  for (int axis = 0; axis < 3; ++axis) {
    SCOPED_TRACE(axis);
    const Vector3 u = Vector3::Unit(axis);
    Vector3 o = Vector3(0.05, -0.03, 0.1);
    o[axis] = -4.0;
    std::array<ShapeHit, 4> hits;
    ASSERT_EQ(intersect_line_with_shape(box, o, u, hits), 2);
    const double h = 0.5 * box.size[axis];
    EXPECT_EQ(hits[0].point_G[axis], -h);
    EXPECT_EQ(hits[1].point_G[axis], h);
    EXPECT_EQ(hits[0].normal_G, -u);
    EXPECT_EQ(hits[1].normal_G, u);
    EXPECT_NEAR(hits[0].lambda, 4.0 - h, 1e-15);
    // Same line, shifted outside the box across a parallel face: a miss.
    o[(axis + 1) % 3] = 0.5;
    EXPECT_EQ(intersect_line_with_shape(box, o, u, hits), 0);
  }
}

TEST(RayPrimitives, LinesAlongTheAxisHitCylinderCapsAndCapsulePoles) {
  std::array<ShapeHit, 4> hits;
  const Vector3 o(0.05, -0.02, 3.0), u = -Vector3::UnitZ();
  ASSERT_EQ(intersect_line_with_shape(test::make_cylinder(0.15, 0.6), o, u, hits), 2);
  EXPECT_EQ(hits[0].point_G.z(), 0.3);
  EXPECT_EQ(hits[0].normal_G, Vector3::UnitZ());
  EXPECT_EQ(hits[1].point_G.z(), -0.3);
  EXPECT_EQ(hits[1].normal_G, -Vector3::UnitZ());
  // Outside the radius, parallel to the axis: no hit.
  EXPECT_EQ(
      intersect_line_with_shape(test::make_cylinder(0.15, 0.6), Vector3(0.2, 0.0, 0.0), u, hits),
      0);
  // Capsule along its axis: the poles at ±(L/2 + r).
  ASSERT_EQ(
      intersect_line_with_shape(test::make_capsule(0.1, 0.5), Vector3(0.0, 0.0, 3.0), u, hits), 2);
  EXPECT_NEAR(hits[0].point_G.z(), 0.35, 1e-15);
  EXPECT_NEAR(hits[1].point_G.z(), -0.35, 1e-15);
  EXPECT_LT((hits[0].normal_G - Vector3::UnitZ()).norm(), 1e-15);
}

TEST(RayPrimitives, QueriesDoNotAllocate) {
  if (!test::allocation_counting_available()) GTEST_SKIP() << "allocation counting unavailable";
  SeededRng rng(15);
  const auto shapes = primitives();
  std::vector<Vector3> origins, directions;
  for (int i = 0; i < 200; ++i) {
    origins.push_back(rng.uniform_vector3(-1.0, 1.0));
    directions.push_back(random_unit(rng));
  }
  std::array<ShapeHit, 8> hits;
  double sink = 0.0;
  const test::AllocationCounter counter;
  for (const auto& [name, shape] : shapes) {
    for (std::size_t i = 0; i < origins.size(); ++i) {
      sink += intersect_line_with_shape(shape, origins[i], directions[i], hits);
      sink += closest_point_to_line(shape, origins[i], directions[i]).distance;
    }
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace extwrench
