// A property suite spanning several sources, so it keeps its own name (docs/layout.md, Tests).
// The paper's robot (paper Sec. IV, Table II) ships twice: models/paper_arm.yaml (standard DH) and
// models/paper_arm.urdf. Both must be the same robot, and both must be the table of
// docs/method.md#the-papers-experiment.
#include <gtest/gtest.h>

#include "extwrench/io/robot_loader.hpp"
#include "support/io_test_util.hpp"
#include "support/paper_arm_table.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

constexpr double kTol = 1e-12;
// Table II as docs/method.md restates it, written from that table (not from the model files).
using namespace test::paper_arm_table;

RobotDescription load(const char* file) {
  LoadOptions o;
  o.use_ros_package_path = false;
  return load_robot(test::project_models() / file, o);
}

TEST(PaperArm, YamlAndUrdfLoadAsTheSameSevenJointSerialChain) {
  const RobotDescription yaml = load("paper_arm.yaml");
  const RobotDescription urdf = load("paper_arm.urdf");
  for (const Model* m : {&yaml.model, &urdf.model}) {
    EXPECT_EQ(m->nq(), 7);
    EXPECT_TRUE(m->is_serial_chain());
    EXPECT_NEAR(m->total_mass(), 2.0 + 5 * 2.7 + 1.7 + 0.3, kTol);
    EXPECT_TRUE(m->gravity.isApprox(Vector3(0, 0, -9.81)));
    for (int i = 0; i <= 7; ++i) EXPECT_EQ(m->body_index("link" + std::to_string(i)), i);
  }
}

TEST(PaperArm, LinkFramesAreTheDhFramesOfTheSpecAtRandomConfigurations) {
  const RobotDescription yaml = load("paper_arm.yaml");
  const RobotDescription urdf = load("paper_arm.urdf");
  test::SeededRng rng(42);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorX q = rng.uniform_vector(7, -kPi, kPi);
    const auto Xy = test::body_poses(yaml.model, q);
    const auto Xu = test::body_poses(urdf.model, q);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();  // frame 0 = world
    for (int i = 0; i <= 7; ++i) {
      if (i > 0) T = T * test::dh_standard(0.0, kAlpha[i - 1], kD[i - 1], q[i - 1]);
      const std::string name = "link" + std::to_string(i);
      EXPECT_TRUE(test::near(test::world_frame_pose(yaml.model, Xy, name), T, 1e-12))
          << "yaml " << name;
      EXPECT_TRUE(test::near(test::world_frame_pose(urdf.model, Xu, name), T, 1e-12))
          << "urdf " << name;
    }
    // The base sensor S: 0.31 m below O_0, parallel to frame 0, whatever q.
    Eigen::Isometry3d S = Eigen::Isometry3d::Identity();
    S.translation() = Eigen::Vector3d(0, 0, -kLink0Height);
    EXPECT_TRUE(test::near(test::world_frame_pose(yaml.model, Xy, "sensor"), S, kTol));
    EXPECT_TRUE(test::near(test::world_frame_pose(urdf.model, Xu, "sensor"), S, kTol));
  }
}

TEST(PaperArm, MassPropertiesAreTheSpecTableInTheDhFrames) {
  for (const char* file : {"paper_arm.yaml", "paper_arm.urdf"}) {
    const Model m = load(file).model;
    // Link 0: CoM 0.15 m above O_s = 0.31 m below O_0.
    EXPECT_NEAR(m.bodies[0].inertia.mass, kLink0Mass, kTol) << file;
    EXPECT_TRUE(m.bodies[0].inertia.com.isApprox(Vector3(0, 0, kLink0ComZ - kLink0Height), kTol))
        << file;
    EXPECT_TRUE(m.bodies[0].inertia.inertia_com.isApprox(
        Vector3(kLink0Inertia[0], kLink0Inertia[1], kLink0Inertia[2]).asDiagonal().toDenseMatrix(),
        kTol));
    for (int i = 1; i <= 7; ++i) {
      const Inertia& in = m.bodies[static_cast<std::size_t>(i)].inertia;
      const double* I = kInertiaGm2[i - 1];
      Matrix3 expected;
      expected << I[0], I[1], I[2], I[1], I[3], I[4], I[2], I[4], I[5];
      EXPECT_NEAR(in.mass, kMass[i - 1], kTol) << file << " link " << i;
      EXPECT_LE(
          (in.com - Vector3(kComCm[i - 1][0], kComCm[i - 1][1], kComCm[i - 1][2]) / 100.0).norm(),
          1e-12)
          << file << " link " << i;
      EXPECT_LE((in.inertia_com - expected * 1e-3).cwiseAbs().maxCoeff(), 1e-12)
          << file << " link " << i;
    }
  }
}

TEST(PaperArm, YamlAndUrdfHaveTheSameCollisionCapsules) {
  const RobotDescription yaml = load("paper_arm.yaml");
  const RobotDescription urdf = load("paper_arm.urdf");
  ASSERT_EQ(yaml.geometry.shapes.size(), urdf.geometry.shapes.size());
  ASSERT_EQ(yaml.geometry.body_shapes.size(), 8u);
  for (std::size_t b = 0; b < 8; ++b) {
    ASSERT_EQ(yaml.geometry.body_shapes[b].size(), 1u) << "one capsule around every link";
    ASSERT_EQ(urdf.geometry.body_shapes[b].size(), 1u);
    const CollisionShape& y =
        yaml.geometry.shapes[static_cast<std::size_t>(yaml.geometry.body_shapes[b][0])];
    const CollisionShape& u =
        urdf.geometry.shapes[static_cast<std::size_t>(urdf.geometry.body_shapes[b][0])];
    EXPECT_EQ(y.type, ShapeType::kCapsule);
    EXPECT_EQ(u.type, ShapeType::kCapsule);
    EXPECT_EQ(y.body, static_cast<int>(b));
    EXPECT_EQ(u.body, static_cast<int>(b));
    EXPECT_DOUBLE_EQ(y.radius, u.radius);
    EXPECT_DOUBLE_EQ(y.length, u.length);
    EXPECT_TRUE(y.placement.is_approx(u.placement, 1e-12)) << "link " << b;
    // Plausible LWR-like sizes, and each capsule contains its link's CoM.
    EXPECT_GE(y.radius, 0.04);
    EXPECT_LE(y.radius, 0.08);
    const Vector3 c =
        y.placement.inverse().act(yaml.model.bodies[b].inertia.com);  // CoM in the capsule frame
    const double along = std::clamp(c.z(), -y.length / 2, y.length / 2);
    EXPECT_LT((c - Vector3(0, 0, along)).norm(), y.radius)
        << "CoM of link " << b << " outside its capsule";
  }
}

TEST(PaperArm, JointDataAgreeBetweenYamlAndUrdf) {
  const Model y = load("paper_arm.yaml").model;
  const Model u = load("paper_arm.urdf").model;
  for (int i = 1; i <= 7; ++i) {
    const Joint& a = y.joints[static_cast<std::size_t>(i)];
    const Joint& b = u.joints[static_cast<std::size_t>(i)];
    EXPECT_EQ(a.name, b.name);
    EXPECT_TRUE(a.axis.isApprox(b.axis, 1e-12) || (a.axis - b.axis).norm() < 1e-12);
    EXPECT_TRUE(a.placement.is_approx(b.placement, 1e-12));
    EXPECT_DOUBLE_EQ(a.lower, b.lower);
    EXPECT_DOUBLE_EQ(a.upper, b.upper);
    EXPECT_DOUBLE_EQ(a.velocity_limit, b.velocity_limit);
    EXPECT_DOUBLE_EQ(a.effort_limit, b.effort_limit);
  }
}

}  // namespace
}  // namespace extwrench
