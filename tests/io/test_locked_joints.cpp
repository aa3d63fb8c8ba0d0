// Locked joints (LoadOptions::locked_joints, ModelBuilder::lock_joint): the reduced model of a
// tree equals the one built from the same URDF whose locked joints are made fixed by a text
// edit (the fixed-joint merge is checked against KDL in tests/reference/test_urdf_kdl.cpp), and
// bad locks get clear errors. Also the tree error and package:// resolution messages.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/estimation/estimator_options.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "support/error_of.hpp"
#include "support/io_test_util.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

const fs::path kTree = fs::path(EXTWRENCH_TEST_DATA_DIR) / "robots/gripper_tree.urdf";

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

LoadOptions locks(std::map<std::string, double> values) {
  LoadOptions o;
  o.use_ros_package_path = false;
  o.locked_joints = std::move(values);
  return o;
}

std::string load_error(const LoadOptions& o) {
  try {
    (void)load_robot(kTree, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void expect_same_inertia(const Inertia& a, const Inertia& b, const std::string& what) {
  EXPECT_NEAR(a.mass, b.mass, 1e-12) << what;
  EXPECT_LT((a.com - b.com).norm(), 1e-12) << what;
  EXPECT_LT((a.inertia_com - b.inertia_com).cwiseAbs().maxCoeff(), 1e-12) << what;
}

TEST(LockedJoints, TheReducedTreeEqualsTheUrdfWithThoseJointsFixed) {
  // finger_slide (prismatic along y) at 0.03 m, finger_hinge (revolute about x) at 0.5 rad.
  const RobotDescription locked =
      load_robot(kTree, locks({{"finger_slide", 0.03}, {"finger_hinge", 0.5}}));
  std::string xml = read(kTree);
  xml = replaced(xml, R"(name="finger_slide" type="prismatic")",
                 R"(name="finger_slide" type="fixed")");
  xml = replaced(xml, R"(<origin xyz="0 0.01 0.07" rpy="0 0 0"/>)",
                 R"(<origin xyz="0 0.04 0.07" rpy="0 0 0"/>)");
  xml = replaced(xml, R"(name="finger_hinge" type="revolute")",
                 R"(name="finger_hinge" type="fixed")");
  xml = replaced(xml, R"(<origin xyz="0.005 -0.02 0.07" rpy="0 0 0"/>)",
                 R"(<origin xyz="0.005 -0.02 0.07" rpy="0.5 0 0"/>)");
  const RobotDescription fixed = load_urdf_string(xml, "fixed.urdf", locks({}));
  const Model& a = locked.model;
  const Model& b = fixed.model;
  ASSERT_EQ(a.nq(), 2);
  ASSERT_TRUE(a.is_serial_chain());
  ASSERT_EQ(a.num_bodies(), b.num_bodies());
  for (int i = 0; i < a.num_bodies(); ++i) {
    const auto ui = static_cast<std::size_t>(i);
    EXPECT_EQ(a.bodies[ui].name, b.bodies[ui].name);
    expect_same_inertia(a.bodies[ui].inertia, b.bodies[ui].inertia, a.bodies[ui].name);
    if (i > 0) {
      EXPECT_TRUE(a.joints[ui].placement.is_approx(b.joints[ui].placement, 1e-14));
    }
  }
  // The fingers' mass is in the last body: the hand's, composed with them.
  EXPECT_NEAR(a.bodies.back().inertia.mass, 1.0 + 0.5 + 0.05 + 0.04, 1e-12);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (const Frame& f : b.frames) {
    const auto k = a.find_frame(f.name);
    ASSERT_TRUE(k) << f.name;
    const Frame& g = a.frames[static_cast<std::size_t>(*k)];
    EXPECT_EQ(g.body, f.body) << f.name;
    EXPECT_TRUE(g.placement.is_approx(f.placement, 1e-14)) << f.name;
  }
  ASSERT_EQ(locked.geometry.shapes.size(), fixed.geometry.shapes.size());
  for (std::size_t s = 0; s < fixed.geometry.shapes.size(); ++s) {
    EXPECT_EQ(locked.geometry.shapes[s].link, fixed.geometry.shapes[s].link);
    EXPECT_EQ(locked.geometry.shapes[s].body, fixed.geometry.shapes[s].body);
    EXPECT_TRUE(
        locked.geometry.shapes[s].placement.is_approx(fixed.geometry.shapes[s].placement, 1e-14));
  }
  // The hinge's tip frame turned with the locked angle: 5 cm along the rotated z axis.
  const Frame& tip = a.frames[static_cast<std::size_t>(*a.find_frame("finger_b_tip"))];
  const Frame& hand = a.frames[static_cast<std::size_t>(*a.find_frame("hand"))];
  const Vector3 offset_hand = hand.placement.rotation.transpose() *
                              (tip.placement.translation - hand.placement.translation);
  EXPECT_LT(
      (offset_hand - Vector3(0.005, -0.02 - 0.05 * std::sin(0.5), 0.07 + 0.05 * std::cos(0.5)))
          .norm(),
      1e-14);
}

TEST(LockedJoints, AChainJointCanBeLockedToo) {
  const Model m =
      load_robot(kTree, locks({{"finger_slide", 0}, {"finger_hinge", 0}, {"elbow", -1.0}})).model;
  EXPECT_EQ(m.nq(), 1);
  EXPECT_EQ(m.joints[1].name, "shoulder");
  EXPECT_EQ(m.body_index("hand"), 1);
}

// A <mimic> follower of a locked joint would stay free (the Panda's second finger became q8, met
// later as a missing log column): refused, with the value its <mimic> gives.
TEST(LockedJoints, TheFollowerOfALockedMimicLeaderIsNamedWithItsValue) {
  const std::string xml =
      replaced(read(kTree), "<limit lower=\"-1\" upper=\"1\" effort=\"5\" velocity=\"1\"/>",
               "<limit lower=\"-1\" upper=\"1\" effort=\"5\" velocity=\"1\"/>\n"
               "    <mimic joint=\"finger_slide\" multiplier=\"10\" offset=\"0.1\"/>");
  const std::string what = test::error_of([&] {
    (void)load_urdf_string(xml, "mimic.urdf", locks({{"finger_slide", 0.02}}));
  });
  EXPECT_NE(what.find("mimic.urdf:"), std::string::npos) << what;
  EXPECT_NE(what.find("joint 'finger_hinge': follows joint 'finger_slide' (<mimic>), which is "
                      "locked: lock it too, at 0.3 (--lock finger_hinge=0.3)"),
            std::string::npos)
      << what;
  EXPECT_EQ(
      load_urdf_string(xml, "mimic.urdf", locks({{"finger_slide", 0.02}, {"finger_hinge", 0.3}}))
          .model.nq(),
      2);
  EXPECT_EQ(load_urdf_string(xml, "mimic.urdf", locks({})).model.nq(), 4);  // no lock: joints
  // A leader locked outside its limits [0, 0.04] is that error, not advice to lock the follower
  // at a value derived from it (a review: the Panda's finger at 0.5).
  const std::string outside = test::error_of([&] {
    (void)load_urdf_string(xml, "mimic.urdf", locks({{"finger_slide", 0.5}}));
  });
  EXPECT_NE(outside.find("locked value 0.5 is outside the joint's limits [0, 0.04]"),
            std::string::npos)
      << outside;
  EXPECT_EQ(outside.find("lock it too"), std::string::npos) << outside;
}

TEST(LockedJoints, BadLocksAreClearErrors) {
  std::string e = load_error(locks({{"finger_slid", 0.0}}));
  EXPECT_NE(e.find("joint 'finger_slid': no such joint in robot 'gripper_tree'"), std::string::npos)
      << e;
  EXPECT_NE(e.find("'shoulder', 'elbow', 'finger_slide', 'finger_hinge'"), std::string::npos) << e;
  e = load_error(locks({{"finger_slide", 0.05}}));
  EXPECT_NE(e.find("locked value 0.05 is outside the joint's limits [0, 0.04]"), std::string::npos)
      << e;
  EXPECT_NE(e.find("gripper_tree.urdf:"), std::string::npos) << e;  // where the joint is
  e = load_error(locks({{"finger_hinge", std::numeric_limits<double>::quiet_NaN()}}));
  EXPECT_NE(e.find("locked value: expected a finite number"), std::string::npos) << e;
  e = load_error(locks({{"wrist_mount", 0.0}}));
  EXPECT_NE(e.find("is already fixed"), std::string::npos) << e;
  LoadOptions o = locks({{"nope", 1.0}});
  o.locked_joint_sources["nope"] = "--lock nope=1";
  e = load_error(o);
  EXPECT_EQ(e.rfind("--lock nope=1: joint 'nope'", 0), 0u) << e;
}

TEST(LockedJoints, TheTreeErrorListsTheBranchesAndSuggestsLocking) {
  const Model tree = load_robot(kTree, locks({})).model;
  ASSERT_FALSE(tree.is_serial_chain());
  EXPECT_EQ(describe_branches(tree), "body 'fore': branch 'finger_slide', branch 'finger_hinge'");
  const EstimatorOptions defaults;  // a named object: gcc 12 warns on the temporary's storage
  try {
    validate(defaults, tree);
    FAIL() << "a tree was accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("not a serial chain"), std::string::npos) << msg;
    EXPECT_NE(msg.find("branch 'finger_slide', branch 'finger_hinge'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--lock NAME=VALUE"), std::string::npos) << msg;
    EXPECT_NE(msg.find("locked_joints: {NAME: VALUE}"), std::string::npos) << msg;
  }
  EXPECT_EQ(
      describe_branches(load_robot(kTree, locks({{"finger_slide", 0}, {"finger_hinge", 0}})).model),
      "");
}

TEST(LockedJoints, ConfigurationsLockJointsAndWriteTheLocksBack) {
  const fs::path dir =
      fs::temp_directory_path() / ("extwrench_locks_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string config = "robot: " + kTree.string() +
                             "\nlocked_joints: {finger_slide: 0.01, finger_hinge: -0.2}\n"
                             "sensor: {type: ft}\n";
  { std::ofstream(dir / "config.yaml") << config; }
  LoadOptions cli;
  cli.locked_joints = {{"finger_hinge", 0.3}};  // the command line wins over the file
  const EstimatorConfig c = load_estimator_config(dir / "config.yaml", cli);
  EXPECT_EQ(c.robot.model.nq(), 2);
  EXPECT_EQ(c.locked_joints.at("finger_slide"), 0.01);
  EXPECT_EQ(c.locked_joints.at("finger_hinge"), 0.3);
  const std::string yaml = to_yaml(c, dir);
  EXPECT_NE(yaml.find("locked_joints: {finger_hinge: 0.29999999999999999, finger_slide: 0.01}"),
            std::string::npos)
      << yaml;
  // A bad value names the file, the line and the key.
  {
    std::ofstream(dir / "bad.yaml") << "robot: " + kTree.string() +
                                           "\nlocked_joints:\n  finger_slide: 0.5\nsensor: {type: "
                                           "ft}\n";
  }
  try {
    (void)load_estimator_config(dir / "bad.yaml");
    FAIL() << "accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad.yaml:3: locked_joints.finger_slide: joint 'finger_slide'"),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("outside the joint's limits"), std::string::npos) << msg;
  }
  // Without the locks the tree error says what to do.
  { std::ofstream(dir / "tree.yaml") << "robot: " + kTree.string() + "\nsensor: {type: ft}\n"; }
  try {
    (void)load_estimator_config(dir / "tree.yaml");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("locked_joints"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

#define REQUIRE_SHARED() \
  if (!test::have_shared()) GTEST_SKIP() << "no shared models at " << test::shared_models()

fs::path panda_dir() { return test::shared_models() / "franka_panda/urdf_example-robot-data"; }

TEST(PackagePath, ADirectoryHoldingTheMeshesUnderATrailingPartOfThePathWorks) {
  REQUIRE_SHARED();
  // panda.urdf names package://example-robot-data/robots/panda_description/meshes/...; the
  // shared copy holds meshes/collision/*.stl: its own directory is enough.
  LoadOptions o = locks({{"panda_finger_joint1", 0.02}, {"panda_finger_joint2", 0.02}});
  o.package_path = {panda_dir()};
  const RobotDescription r = load_robot(panda_dir() / "urdf/panda.urdf", o);
  EXPECT_EQ(r.model.nq(), 7);
  EXPECT_TRUE(r.model.is_serial_chain());
  int meshes = 0;
  for (const CollisionShape& s : r.geometry.shapes) {
    if (s.type != ShapeType::kMesh) continue;
    ++meshes;
    ASSERT_TRUE(s.mesh);
    EXPECT_GT(s.mesh->triangles.cols(), 0);
    EXPECT_EQ(fs::path(s.mesh->path).parent_path(), panda_dir() / "meshes/collision");
  }
  EXPECT_EQ(meshes, 9);  // link0..link7 and the hand (the fingers are primitives)
}

TEST(PackagePath, TheErrorNamesTheOptionAndTheDirectoriesSearched) {
  REQUIRE_SHARED();
  LoadOptions o;
  o.use_ros_package_path = false;
  o.package_path = {"/nonexistent/a", "/nonexistent/b"};
  std::string msg;
  try {
    (void)load_robot(panda_dir() / "urdf/panda.urdf", o);
  } catch (const Error& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("--package-path"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("LoadOptions"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'/nonexistent/a', '/nonexistent/b'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("package 'example-robot-data'"), std::string::npos) << msg;
  o.package_path.clear();
  try {
    (void)load_robot(panda_dir() / "urdf/panda.urdf", o);
  } catch (const Error& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("directories searched: none"), std::string::npos) << msg;
}

}  // namespace
}  // namespace extwrench
