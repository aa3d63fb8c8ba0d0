// Acceptance 3 of issue 3 at the estimator level: on the Panda's collision meshes
// (../shared/models, loaded by our URDF loader with assimp + Embree), a force pushing on a link's
// surface is located at its pushing point, never at the pulling one, and a line that misses the
// link says so. The wrench data come from KDL (its own URDF parser, RNE with the wrench).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <filesystem>

#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "reference/kdl_reference.hpp"
#include "reference/panda_chain.hpp"
#include "support/build_info.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

using test::panda_chain;
const std::filesystem::path kUrdf = test::panda_urdf();

/// A base F/T sensor and thresholds that declare any contact on its first sample.
EstimatorOptions sensitive_ft_options() {
  EstimatorOptions opt;
  opt.sensor.type = SensorType::kForceTorque;
  opt.detection.tau_min = VectorX::Constant(1, 1e-9);
  opt.detection.f_min = 1e-9;
  opt.detection.min_duration = 0.0;
  return opt;
}

/// A configuration away from the joint limits and singularities.
VectorX test_configuration() {
  VectorX q(7);
  q << 0.1, -0.4, 0.2, -2.0, 0.1, 1.6, 0.5;
  return q;
}

TEST(PandaMeshContact, PushingPointIsNeverConfusedWithThePullingOne) {
  if (!std::filesystem::exists(kUrdf)) GTEST_SKIP() << "shared models absent";
  const RobotDescription robot = panda_chain();
  const Model& model = robot.model;
  ASSERT_EQ(model.nq(), 7);
  ASSERT_TRUE(model.is_serial_chain());
  test::KdlReference kdl(model);
  ContactEstimator est(model, robot.geometry, sensitive_ft_options());
  SeededRng rng(31);
  double t = 0.0;
  int exact = 0, earlier = 0, total = 0;
  for (int link = 1; link <= 7; ++link) {
    const auto& shapes = robot.geometry.body_shapes[link];
    if (shapes.empty()) continue;
    for (int k = 0; k < 100; ++k) {
      const CollisionShape& shape =
          robot.geometry
              .shapes[shapes[static_cast<std::size_t>(rng.uniform(0, shapes.size() - 1e-9))]];
      if (shape.type != ShapeType::kMesh || !shape.mesh) continue;
      const TriangleMesh& mesh = *shape.mesh;
      // A random point of a random triangle (area-agnostic), its outward normal (winding).
      const int tri = static_cast<int>(rng.uniform(0, mesh.triangles.cols() - 1e-9));
      const Vector3 a = mesh.vertices.col(mesh.triangles(0, tri)),
                    b = mesh.vertices.col(mesh.triangles(1, tri)),
                    c = mesh.vertices.col(mesh.triangles(2, tri));
      const Vector3 cross = (b - a).cross(c - a);
      if (cross.norm() < 1e-10) continue;  // degenerate triangle
      double u = rng.uniform(0.02, 0.98), v = rng.uniform(0.02, 0.98);
      if (u + v > 1.0) {  // fold back into the triangle
        u = 1.0 - u;
        v = 1.0 - v;
      }
      const Vector3 p_S = a + u * (b - a) + v * (c - a);
      const VectorX q = rng.uniform_vector(7, -1.5, 1.5), zero = VectorX::Zero(7);
      const Pose X_WL = kdl.compute_body_pose(q, link);
      const Pose X_WS = X_WL * shape.placement;
      const Vector3 p_W = X_WS.act(p_S), n_W = X_WS.rotation * cross.normalized();
      Vector3 dir = rng.uniform_vector3(-1, 1).normalized();
      if (dir.dot(n_W) > 0) dir = -dir;
      if (dir.dot(n_W) > -0.3) dir = (dir - n_W).normalized();
      const Vector3 F = 15.0 * dir;  // pushes into the surface at p
      const auto ref = kdl.compute(q, zero, zero, link, F, p_W, Vector3::Zero());
      t += 1e-3;
      ASSERT_TRUE(est.update_with(t, q, zero, zero, ref.tau_ext, ref.tau,
                                  test::to_sensor_frame(ref.reading_W, Pose{}))
                      .ok());
      const ContactEstimate& e = est.result();
      ASSERT_EQ(e.link, link);
      ASSERT_TRUE(e.has(EstimateFlag::kLineOfAction));
      const Vector3& dir_hat = e.line_direction_W;
      const Vector3 d = p_W - e.line_point_W;
      EXPECT_LE((d - d.dot(dir_hat) * dir_hat).norm(), 1e-6) << "link " << link;
      ASSERT_TRUE(e.has(EstimateFlag::kSurfacePoint)) << "link " << link;
      ++total;
      // λ along the line: the true point at λ_p; the estimate must never lie beyond it (that
      // would be a pulling point). When the line enters the link first at p, it must be p.
      const double lambda_p = d.dot(dir_hat);
      const double lambda_e = (e.point_W - e.line_point_W).dot(dir_hat);
      EXPECT_LE(lambda_e, lambda_p + 1e-5) << "link " << link << " sample " << k;
      if ((e.point_W - p_W).norm() <= 1e-5) {
        ++exact;
      } else {
        ++earlier;  // the line crossed the link (another part of a non-convex mesh) before p
      }
    }
  }
  ASSERT_GT(total, 300);
  // Most pushes on a link's outer surface enter it right there.
  EXPECT_GT(exact, 0.8 * total) << exact << " exact, " << earlier << " entered earlier";
}

TEST(PandaMeshContact, ALineThatMissesTheLinkReportsTheNearestSurfacePoint) {
  if (!std::filesystem::exists(kUrdf)) GTEST_SKIP() << "shared models absent";
  const RobotDescription robot = panda_chain();
  const Model& model = robot.model;
  test::KdlReference kdl(model);
  ContactEstimator est(model, robot.geometry, sensitive_ft_options());
  const VectorX q = test_configuration();
  const VectorX zero = VectorX::Zero(7);
  // A force along y applied to a point rigidly attached to link 4, 0.6 m along its x axis: its
  // line stays ~0.6 m from the link's mesh, and τ_ext,4 = 7.2 N m isolates link 4.
  const Pose X = kdl.compute_body_pose(q, 4);
  const Vector3 offset = X.rotation * Vector3(0.6, 0.0, 0.0);
  const Vector3 F = X.rotation * Vector3(0.0, 12.0, 0.0);
  const auto ref = kdl.compute(q, zero, zero, 4, F, X.translation + offset, Vector3::Zero());
  ASSERT_TRUE(est.update_with(0.0, q, zero, zero, ref.tau_ext, ref.tau,
                              test::to_sensor_frame(ref.reading_W, Pose{}))
                  .ok());
  const ContactEstimate& e = est.result();
  ASSERT_EQ(e.link, 4);
  EXPECT_TRUE(e.has(EstimateFlag::kSurfaceMissed));
  EXPECT_FALSE(e.has(EstimateFlag::kSurfacePoint));
  EXPECT_GT(e.surface_distance, 0.3);
  EXPECT_TRUE(e.point_W.allFinite());
}

long thread_page_faults() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt + usage.ru_majflt;
}

// The constructor's warm_up: the first contact's update finds the ray casting code (Embree's
// traversal kernels, first used by that update) paged in. Without it that update took 4-5 page
// faults in libembree (BM_FirstUpdates_Ours, BENCHMARKS.md). ctest runs each test in its own
// process, so nothing before this test has cast a ray.
TEST(PandaMeshContact, TheFirstContactFindsTheRayCastingCodePagedIn) {
  if (!std::filesystem::exists(kUrdf)) GTEST_SKIP() << "shared models absent";
  const RobotDescription robot = panda_chain();
  const Model& model = robot.model;
  test::KdlReference kdl(model);
  const ContactEstimator prototype(model, robot.geometry, sensitive_ft_options());
  const VectorX q = test_configuration();
  const VectorX zero = VectorX::Zero(7);
  // 15 N pushing along −x of link 6's frame on the face of its mesh that looks along +x.
  const int link = 6;
  const CollisionShape* mesh_shape = nullptr;
  for (int s : robot.geometry.body_shapes[link]) {
    const CollisionShape& shape = robot.geometry.shapes[static_cast<std::size_t>(s)];
    if (shape.type == ShapeType::kMesh && shape.mesh) mesh_shape = &shape;
  }
  ASSERT_NE(mesh_shape, nullptr);
  Vector3 p_L = Vector3::Constant(-1e300);
  for (Eigen::Index v = 0; v < mesh_shape->mesh->vertices.cols(); ++v) {
    const Vector3 p = mesh_shape->placement.act(mesh_shape->mesh->vertices.col(v));
    if (p.x() > p_L.x()) p_L = p;
  }
  const Pose X_WL = kdl.compute_body_pose(q, link);
  const Vector3 F = X_WL.rotation * Vector3(-15.0, 4.0, 0.0);
  const auto ref = kdl.compute(q, zero, zero, link, F, X_WL.act(p_L), Vector3::Zero());
  const Vector6 reading = test::to_sensor_frame(ref.reading_W, Pose{});
  // Copies (their buffers touched once by a first update at rest), then the contact, measured.
  ContactEstimator est = prototype;
  const auto rest = kdl.compute(q, zero, zero, link, Vector3::Zero(), p_L, Vector3::Zero());
  ASSERT_TRUE(est.update_with(0.0, q, zero, zero, zero, rest.tau,
                              test::to_sensor_frame(rest.reading_W, Pose{}))
                  .ok());
  ASSERT_FALSE(est.result().contact);
  const long before = thread_page_faults();
  const Status status = est.update_with(1e-3, q, zero, zero, ref.tau_ext, ref.tau, reading);
  const long faults = thread_page_faults() - before;
  ASSERT_TRUE(status.ok());
  const ContactEstimate& e = est.result();
  ASSERT_TRUE(e.contact);
  ASSERT_EQ(e.link, link);
  ASSERT_TRUE(e.has(EstimateFlag::kSurfacePoint));  // the update did cast against the mesh
  // AddressSanitizer maps its shadow memory lazily: its own page faults say nothing of ours.
  if (test::kSanitizerBuild) return;
  EXPECT_EQ(faults, 0) << "page faults in the first contact's update";
}

}  // namespace
}  // namespace extwrench
