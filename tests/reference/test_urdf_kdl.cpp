// Our URDF loader against KDL built by its own parser (kdl_parser): link poses and merged
// world-frame mass properties of the shared robots (moved here from tests/io/test_urdf.cpp so
// that only tests/reference/ links KDL).
#include <gtest/gtest.h>

#include <filesystem>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <vector>

#include "extwrench/io/robot_loader.hpp"
#include "support/io_test_util.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

using test::no_meshes;

fs::path panda_dir() { return test::shared_models() / "franka_panda/urdf_example-robot-data"; }
fs::path lwr_dir() { return test::shared_models() / "kuka_lwr4plus/urdf_flobaroid"; }

#define REQUIRE_SHARED() \
  if (!test::have_shared()) GTEST_SKIP() << "no shared models at " << test::shared_models()

Pose from_kdl(const KDL::Frame& f) {
  Pose x;
  for (int r = 0; r < 3; ++r) {
    x.translation[r] = f.p(r);
    for (int c = 0; c < 3; ++c) x.rotation(r, c) = f.M(r, c);
  }
  return x;
}

void compare_with_kdl(const fs::path& file) {
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromFile(file.string(), tree)) << file;
  const Model m = load_robot(file, no_meshes()).model;
  ASSERT_EQ(static_cast<int>(tree.getNrOfJoints()), m.nq());
  KDL::TreeFkSolverPos_recursive fk(tree);
  test::SeededRng rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const VectorX q = rng.uniform_vector(m.nq(), -1.5, 1.5);
    const auto X = test::body_poses(m, q);
    KDL::JntArray qk(tree.getNrOfJoints());
    for (const auto& [name, seg] : tree.getSegments()) {
      const KDL::Joint& j = seg.segment.getJoint();
      if (j.getType() == KDL::Joint::None) continue;
      qk(seg.q_nr) = q[*m.find_joint(j.getName()) - 1];
    }
    // Every link: pose, and the world-frame mass properties of every moving body (KDL drops
    // the root link's inertia, so body 0 is left out).
    std::vector<KDL::RigidBodyInertia> body_inertia(static_cast<std::size_t>(m.num_bodies()),
                                                    KDL::RigidBodyInertia::Zero());
    for (const auto& [name, seg] : tree.getSegments()) {
      if (name == tree.getRootSegment()->first) continue;
      KDL::Frame f;
      ASSERT_GE(fk.JntToCart(qk, f, name), 0);
      const Pose ours = test::world_frame_pose(m, X, name);
      EXPECT_TRUE(ours.is_approx(from_kdl(f), 1e-9)) << file.filename() << " link " << name;
      body_inertia[static_cast<std::size_t>(*m.find_body(name))] =
          body_inertia[static_cast<std::size_t>(*m.find_body(name))] + f * seg.segment.getInertia();
    }
    for (int b = 1; b < m.num_bodies(); ++b) {
      const KDL::RigidBodyInertia& k = body_inertia[static_cast<std::size_t>(b)];
      const Inertia w =
          m.bodies[static_cast<std::size_t>(b)].inertia.transformed(X[static_cast<std::size_t>(b)]);
      EXPECT_NEAR(w.mass, k.getMass(), 1e-9);
      if (k.getMass() > 0) {
        for (int i = 0; i < 3; ++i)
          EXPECT_NEAR(w.com[i], k.getCOG()(i), 1e-9) << file.filename() << " body " << b;
      }
      // KDL's rotational inertia is about the reference (world) origin.
      const Matrix3 about_origin =
          w.inertia_com +
          w.mass * (w.com.squaredNorm() * Matrix3::Identity() - w.com * w.com.transpose());
      const KDL::RotationalInertia ki = k.getRotationalInertia();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(about_origin(r, c), ki.data[3 * r + c], 1e-9)
              << file.filename() << " body " << b;
      }
    }
  }
}

TEST(UrdfShared, PandaKinematicsAndMergedInertiasMatchKdl) {
  REQUIRE_SHARED();
  compare_with_kdl(panda_dir() / "urdf/panda.urdf");
}

TEST(UrdfShared, Ur5AndLwrKinematicsAndMergedInertiasMatchKdl) {
  REQUIRE_SHARED();
  compare_with_kdl(test::shared_models() / "ur5/urdf_example-robot-data/urdf/ur5_robot.urdf");
  compare_with_kdl(lwr_dir() / "kuka_lwr4.urdf");
}

}  // namespace
}  // namespace extwrench
