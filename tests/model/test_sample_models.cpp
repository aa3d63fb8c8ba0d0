// The sample models: paper_arm() is the paper's table (written again, independently, in
// tests/support/paper_arm_table.hpp) and the robot of models/paper_arm.urdf; random_chain is
// reproducible and physically valid.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <filesystem>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/sample_models.hpp"
#include "support/paper_arm_table.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using namespace test::paper_arm_table;

TEST(PaperArm, IsTheTableInTheDhFrames) {
  const Model m = paper_arm();
  ASSERT_EQ(m.nq(), 7);
  EXPECT_TRUE(m.is_serial_chain());
  EXPECT_DOUBLE_EQ(m.bodies[0].inertia.mass, kLink0Mass);
  EXPECT_DOUBLE_EQ(m.bodies[0].inertia.com.z(), kLink0ComZ);
  EXPECT_DOUBLE_EQ(m.joints[1].placement.translation.z(), kLink0Height);
  for (int i = 1; i <= 7; ++i) {
    // Back in DH frame i (frame "dh<i>"), the CoM and inertia are the table's.
    const auto dh = m.find_frame("dh" + std::to_string(i));
    ASSERT_TRUE(dh.has_value());
    const Inertia in_dh = m.bodies[i].inertia.transformed(m.frames[*dh].placement.inverse());
    const double* I = kInertiaGm2[i - 1];
    Matrix3 expected;
    expected << I[0], I[1], I[2], I[1], I[3], I[4], I[2], I[4], I[5];
    EXPECT_DOUBLE_EQ(in_dh.mass, kMass[i - 1]);
    EXPECT_LE(
        (in_dh.com - Vector3(kComCm[i - 1][0], kComCm[i - 1][1], kComCm[i - 1][2]) / 100.0).norm(),
        1e-14);
    EXPECT_LE((in_dh.inertia_com - expected * 1e-3).cwiseAbs().maxCoeff(), 1e-14);
  }
}

// The URDF places link 0's frame at O_0 and the sensor 0.31 m below; paper_arm() puts link 0's
// frame on the sensor. Joint-space dynamics do not see that shift of the world origin.
TEST(PaperArm, HasTheDynamicsOfModelsPaperArmUrdf) {
  LoadOptions options;
  options.use_ros_package_path = false;
  const Model urdf =
      load_robot(std::filesystem::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf", options)
          .model;
  const Model ours = paper_arm();
  ASSERT_EQ(urdf.nq(), ours.nq());
  EXPECT_NEAR(urdf.total_mass(), ours.total_mass(), 1e-12);
  Data du(urdf);
  Data dm(ours);
  test::SeededRng rng(3);
  for (int k = 0; k < 50; ++k) {
    const VectorX q = rng.uniform_vector(7, -3, 3), dq = rng.uniform_vector(7, -2, 2),
                  ddq = rng.uniform_vector(7, -5, 5);
    const VectorX tau_urdf = rnea(urdf, du, q, dq, ddq);
    const VectorX tau_ours = rnea(ours, dm, q, dq, ddq);
    EXPECT_LE((tau_urdf - tau_ours).cwiseAbs().maxCoeff(), 1e-10);
    const MatrixX m_urdf = crba(urdf, du, q);
    EXPECT_LE((m_urdf - crba(ours, dm, q)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(RandomChain, IsReproducibleAndValid) {
  const RandomChainOptions options{.n = 9, .tree = true, .prismatic = true, .seed = 17};
  const Model a = random_chain(options);
  const Model b = random_chain(options);
  ASSERT_EQ(a.nq(), 9);
  for (int i = 0; i <= 9; ++i) {
    EXPECT_EQ(a.parents[i], b.parents[i]);
    EXPECT_EQ(a.bodies[i].inertia.mass, b.bodies[i].inertia.mass);
    EXPECT_EQ(a.joints[i].axis, b.joints[i].axis);
    EXPECT_GE(a.bodies[i].inertia.mass, 0.5);
    EXPECT_LT(a.parents[i], i);
    const Eigen::SelfAdjointEigenSolver<Matrix3> eig(a.bodies[i].inertia.inertia_com);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  }
  EXPECT_EQ(a.joints[2].type, JointType::kPrismatic);
  EXPECT_TRUE(random_chain({.n = 5}).is_serial_chain());
  EXPECT_NE(random_chain({.seed = 1}).bodies[3].inertia.mass,
            random_chain({.seed = 2}).bodies[3].inertia.mass);
}

}  // namespace
}  // namespace extwrench
