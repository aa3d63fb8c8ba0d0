#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>

#include "extwrench/core/error.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/io/urdf_writer.hpp"
#include "support/error_of.hpp"
#include "support/io_test_util.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

using test::no_meshes;

std::string load_error(const fs::path& path, const LoadOptions& o) {
  try {
    (void)load_robot(path, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

fs::path panda_dir() { return test::shared_models() / "franka_panda/urdf_example-robot-data"; }
fs::path lwr_dir() { return test::shared_models() / "kuka_lwr4plus/urdf_flobaroid"; }

#define REQUIRE_SHARED() \
  if (!test::have_shared()) GTEST_SKIP() << "no shared models at " << test::shared_models()

// ---- inline URDFs --------------------------------------------------------------------------

TEST(Urdf, InertialOriginIsConvertedToTheLinkFrame) {
  const std::string xml = R"(<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="arm">
    <inertial>
      <origin xyz="0.1 0.2 0.3" rpy="0 0 1.5707963267948966"/>
      <mass value="2"/>
      <inertia ixx="0.3" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.1"/>
    </inertial>
  </link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 3"/></joint>
</robot>)";
  const Model m = load_urdf_string(xml, "inline.urdf", no_meshes()).model;
  const Inertia& in = m.bodies[1].inertia;
  EXPECT_DOUBLE_EQ(in.mass, 2.0);
  EXPECT_TRUE(in.com.isApprox(Vector3(0.1, 0.2, 0.3)));
  // Yaw by 90 deg swaps the x and y principal axes: I_link = diag(0.2, 0.3, 0.1).
  EXPECT_LT(
      (in.inertia_com - Vector3(0.2, 0.3, 0.1).asDiagonal().toDenseMatrix()).cwiseAbs().maxCoeff(),
      1e-15);
  EXPECT_TRUE(m.joints[1].axis.isApprox(Vector3::UnitZ()));
  EXPECT_TRUE(std::isinf(m.joints[1].lower));
}

TEST(Urdf, AnEmptyFileIsCalledEmpty) {
  // tinyxml2's own text was "Error=XML_ERROR_EMPTY_DOCUMENT ErrorID=13 (0xd) Line number=0".
  for (const char* xml : {"", "  \n", "<!-- nothing -->\n"}) {
    try {
      (void)load_urdf_string(xml, "empty.urdf", no_meshes());
      ADD_FAILURE() << "no error for '" << xml << "'";
    } catch (const Error& e) {
      EXPECT_STREQ(e.what(),
                   "empty.urdf: the file is empty (or holds only white space and comments)");
    }
  }
}

TEST(Urdf, NonPhysicalInertiaPointsAtTheProductsOnlyWhenTheDiagonalIsPhysical) {
  // The inertial frame is rotated, so the link-frame tensor has other products than the file:
  // the message quotes the file's.
  const auto xml = [](const std::string& inertia) {
    return R"(<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="arm">
    <inertial>
      <origin xyz="0 0 0" rpy="0.3 0.2 0.1"/>
      <mass value="2"/>
      )" + inertia +
           R"(
    </inertial>
  </link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/></joint>
</robot>)";
  };
  const auto error = [](const std::string& urdf) {
    try {
      (void)load_urdf_string(urdf, "inline.urdf", no_meshes());
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string products = error(
      xml(R"(<inertia ixx="0.01" ixy="0.01" ixz="1e-2" iyy="0.002" iyz="0.01" izz="0.01"/>)"));
  EXPECT_NE(products.find("inline.urdf:7: <inertia> of link 'arm': inertia: not positive "
                          "semi-definite"),
            std::string::npos)
      << products;
  EXPECT_NE(products.find("are the products ixy, ixz, iyz (0.01, 1e-2, 0.01) placeholders?"),
            std::string::npos)
      << products;
  // The diagonal itself breaks the triangle inequality: no products to blame.
  const std::string diagonal =
      error(xml(R"(<inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.01" iyz="0" izz="0.1"/>)"));
  EXPECT_NE(diagonal.find("triangle inequality"), std::string::npos) << diagonal;
  EXPECT_EQ(diagonal.find("placeholders"), std::string::npos) << diagonal;
}

TEST(Urdf, JointLimitsDynamicsAndDefaultsAreKept) {
  const std::string xml = R"(<robot name="r">
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="2" velocity="3" effort="4"/><dynamics damping="0.5" friction="0.25"/>
    <mimic joint="x"/><safety_controller k_velocity="1"/></joint>
  <gazebo><link name="not_a_link"/></gazebo>
  <transmission name="t"><joint name="j"/></transmission>
</robot>)";
  const Model m = load_urdf_string(xml, "inline.urdf", no_meshes()).model;
  ASSERT_EQ(m.nq(), 1);
  const Joint& j = m.joints[1];
  EXPECT_TRUE(j.axis.isApprox(Vector3::UnitX())) << "URDF default axis";
  EXPECT_EQ(j.lower, -1.0);
  EXPECT_EQ(j.upper, 2.0);
  EXPECT_EQ(j.velocity_limit, 3.0);
  EXPECT_EQ(j.effort_limit, 4.0);
  EXPECT_EQ(j.damping, 0.5);
  EXPECT_EQ(j.friction, 0.25);
  EXPECT_FALSE(m.find_frame("not_a_link")) << "links inside extension elements are not links";
}

TEST(Urdf, CollisionShapesOfMergedLinksArePlacedOnTheirBody) {
  const std::string xml = R"(<robot name="r">
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><sphere radius="0.05"/></geometry></collision></link>
  <link name="tool">
    <collision><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/><geometry><capsule radius="0.02" length="0.1"/></geometry></collision>
    <collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision>
    <collision><geometry><cylinder radius="0.1" length="0.2"/></geometry></collision>
    <collision><geometry><mesh filename="package://nowhere/m.stl" scale="2 2 2"/></geometry></collision>
  </link>
  <joint name="j" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/><limit effort="1" velocity="1"/></joint>
  <joint name="f" type="fixed"><parent link="b"/><child link="tool"/><origin xyz="0 0 0.5" rpy="0 0 1.5707963267948966"/></joint>
</robot>)";
  const RobotDescription r = load_urdf_string(xml, "inline.urdf", no_meshes());
  ASSERT_EQ(r.geometry.shapes.size(), 5u);
  ASSERT_EQ(r.geometry.body_shapes[1].size(), 5u);
  const CollisionShape& cap = r.geometry.shapes[1];
  EXPECT_EQ(cap.type, ShapeType::kCapsule);
  EXPECT_EQ(cap.link, "tool");
  EXPECT_EQ(cap.body, 1);
  // X_{b, shape} = X_{b, tool} X_{tool, shape}: the capsule centre is at (0, 0.2, 0.5) in b.
  EXPECT_LT((cap.placement.translation - Vector3(0, 0.2, 0.5)).norm(), 1e-12);
  EXPECT_EQ(r.geometry.shapes[2].size, Vector3(0.1, 0.2, 0.3));
  EXPECT_EQ(r.geometry.shapes[3].type, ShapeType::kCylinder);
  const CollisionShape& mesh = r.geometry.shapes[4];
  EXPECT_EQ(mesh.type, ShapeType::kMesh);
  EXPECT_EQ(mesh.scale, Vector3(2, 2, 2));
  ASSERT_TRUE(mesh.mesh);
  EXPECT_EQ(mesh.mesh->vertices.cols(), 0)
      << "load_meshes = false keeps the shape without triangles";
  // With load_meshes the unresolvable package is an error naming the line and the attribute.
  LoadOptions o = no_meshes();
  o.load_meshes = true;
  try {
    (void)load_urdf_string(xml, "inline.urdf", o);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("inline.urdf:9: <mesh> of link 'tool': attribute 'filename'"),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("package 'nowhere'"), std::string::npos) << msg;
  }
}

TEST(Urdf, GravityCanBeOverridden) {
  const fs::path file = test::project_models() / "paper_arm.urdf";
  EXPECT_TRUE(load_robot(file, no_meshes()).model.gravity.isApprox(Vector3(0, 0, -9.81)));
  LoadOptions o = no_meshes();
  o.gravity = Vector3(0, 9.81, 0);  // a wall-mounted robot
  EXPECT_TRUE(load_robot(file, o).model.gravity.isApprox(Vector3(0, 9.81, 0)));
  EXPECT_TRUE(load_robot(test::project_models() / "paper_arm.yaml", o)
                  .model.gravity.isApprox(Vector3(0, 9.81, 0)));
}

// A rotation about one axis has -0 entries: atan2 turned them into -0 angles, which the written
// URDF (and every configuration and message) carried as "-0" although they read back as +0.
TEST(Urdf, WrittenAnglesAreNeverNegativeZero) {
  for (int a = 0; a < 3; ++a) {
    const Vector3 axis = Vector3::Unit(a);
    const Matrix3 r = Eigen::AngleAxisd(5.0, axis).toRotationMatrix();
    const Vector3 rpy = rpy_from_rotation(r);
    for (int k = 0; k < 3; ++k) {
      if (k == a) continue;  // the angle itself, 5 - 2π
      EXPECT_EQ(rpy[k], 0.0) << axis.transpose();
      EXPECT_FALSE(std::signbit(rpy[k])) << axis.transpose();
    }
    // Still the same rotation.
    const Matrix3 back = (Eigen::AngleAxisd(rpy.z(), Vector3::UnitZ()) *
                          Eigen::AngleAxisd(rpy.y(), Vector3::UnitY()) *
                          Eigen::AngleAxisd(rpy.x(), Vector3::UnitX()))
                             .toRotationMatrix();
    EXPECT_TRUE(back.isApprox(r, 1e-14)) << axis.transpose();
  }
  Model m = load_robot(test::project_models() / "paper_arm.urdf", no_meshes()).model;
  m.joints[1].placement.rotation = Eigen::AngleAxisd(5.0, Vector3::UnitX()).toRotationMatrix();
  const std::string text = write_urdf_string(m, GeometryModel{});
  EXPECT_EQ(text.find("-0 "), std::string::npos) << text;
  EXPECT_EQ(text.find("-0\""), std::string::npos) << text;
}

// A pose at pitch ±π/2 (a wall-mounted sensor, xacro's exact pi/2) and near it: roll and yaw
// read each from rounding-sized entries composed back 0.04 rad off (a review's sensor at
// rpy (0, π/2, 0.7) was estimated with a pose 0.21 rad away). Written and read back, every pose
// is the same rotation to 1e-14, and the written URDF reloads to the same joint placement.
TEST(Urdf, WrittenAnglesKeepTheRotationAtAndNearGimbalLock) {
  const double half_pi = 1.5707963267948966;
  std::vector<Vector3> poses;
  for (const double pitch :
       {half_pi, -half_pi, half_pi - 1e-9, -half_pi + 1e-12, half_pi - 1e-5, 1.3, 0.0, 3.0}) {
    for (const double roll : {0.0, 0.3, -2.9, 3.1})
      for (const double yaw : {0.0, 0.2, 0.7, -1.4}) poses.emplace_back(roll, pitch, yaw);
  }
  for (const Vector3& rpy : poses) {
    const Matrix3 r = Pose::from_xyz_rpy(Vector3::Zero(), rpy).rotation;
    const Vector3 back = rpy_from_rotation(r);
    const Matrix3 again = Pose::from_xyz_rpy(Vector3::Zero(), back).rotation;
    EXPECT_LT((again - r).cwiseAbs().maxCoeff(), 1e-14)
        << rpy.transpose() << " -> " << back.transpose();
  }
  Model m = load_robot(test::project_models() / "paper_arm.urdf", no_meshes()).model;
  m.joints[2].placement.rotation =
      Pose::from_xyz_rpy(Vector3::Zero(), Vector3(0.3, half_pi, 0.2)).rotation;
  const Model reread =
      load_urdf_string(write_urdf_string(m, GeometryModel{}), "written.urdf", no_meshes()).model;
  EXPECT_LT(
      (reread.joints[2].placement.rotation - m.joints[2].placement.rotation).cwiseAbs().maxCoeff(),
      1e-14);
}

// ---- the shared validation models ------------------------------------------------------------

TEST(Urdf, MjcfOnlyOptionsAreRefusedNamingThem) {
  LoadOptions options;
  options.root_body = "link0";
  const fs::path file = test::project_models() / "paper_arm.urdf";
  try {
    (void)load_robot(file, options);
    ADD_FAILURE() << "root_body accepted for a URDF";
  } catch (const Error& e) {
    // Both spellings (the command line's, a configuration's) and what to do.
    EXPECT_NE(std::string(e.what()).find(
                  file.string() + ": a root or tip body ('link0', '') chooses the chain in an MJCF "
                                  "scene (--root-body, --tip-body; root_body, tip_body in a "
                                  "configuration); a URDF or DH table describes one robot already: "
                                  "leave them out"),
              std::string::npos)
        << e.what();
  }
}

TEST(UrdfShared, PandaLoadsAsATreeWithItsFingers) {
  REQUIRE_SHARED();
  const Model m = load_robot(panda_dir() / "urdf/panda.urdf", no_meshes()).model;
  EXPECT_EQ(m.nq(), 9);
  EXPECT_FALSE(m.is_serial_chain());
  EXPECT_EQ(m.bodies[0].name, "panda_link0");
  const int hand = m.body_index("panda_hand");
  EXPECT_EQ(hand, m.body_index("panda_link7"))
      << "hand and link8 merged into link 7 by fixed joints";
  const int left = m.body_index("panda_leftfinger");
  const int right = m.body_index("panda_rightfinger");
  EXPECT_EQ(m.parents[static_cast<std::size_t>(left)], hand);
  EXPECT_EQ(m.parents[static_cast<std::size_t>(right)], hand);
  EXPECT_EQ(m.joints[static_cast<std::size_t>(left)].type, JointType::kPrismatic);
  EXPECT_TRUE(m.find_frame("panda_hand_tcp"));
  // urdfdom's total (models/README.md): 17.4519 kg.
  EXPECT_NEAR(m.total_mass(), 17.4519, 5e-5);
}

TEST(UrdfShared, Ur5LoadsWithItsWorldLinkMerged) {
  REQUIRE_SHARED();
  for (const char* f : {"ur5_robot.urdf", "ur5_joint_limited_robot.urdf"}) {
    const Model m =
        load_robot(test::shared_models() / "ur5/urdf_example-robot-data/urdf" / f, no_meshes())
            .model;
    EXPECT_EQ(m.nq(), 6) << f;
    EXPECT_TRUE(m.is_serial_chain()) << f;
    EXPECT_EQ(m.body_index("base_link"), 0) << f;
    EXPECT_NEAR(m.total_mass(), 20.9939, 5e-5) << f;
  }
}

TEST(UrdfShared, EveryUrdfLoadsExceptTheGazLwrWithItsNonPhysicalInertias) {
  REQUIRE_SHARED();
  int loaded = 0;
  for (const auto& entry : fs::recursive_directory_iterator(test::shared_models())) {
    if (entry.path().extension() != ".urdf") continue;
    const std::string name = entry.path().filename().string();
    if (name.rfind("kuka_lwr4_gaz", 0) == 0) {
      const std::string msg = load_error(entry.path(), no_meshes());
      // lwr_1_link is the first link (in file order) whose inertia is not physical.
      EXPECT_NE(msg.find("link 'lwr_1_link'"), std::string::npos) << name << ": " << msg;
      EXPECT_NE(msg.find("not positive semi-definite"), std::string::npos) << name << ": " << msg;
      // Its diagonal is physical; the file's products are 0.01 (placeholders).
      EXPECT_NE(msg.find("are the products ixy, ixz, iyz (0.01, 0.01, 0.01) placeholders?"),
                std::string::npos)
          << msg;
      EXPECT_NE(msg.find(name + ":"), std::string::npos) << msg;
      continue;
    }
    EXPECT_NO_THROW((void)load_robot(entry.path(), no_meshes())) << name;
    ++loaded;
  }
  EXPECT_EQ(loaded, 10);
}

TEST(UrdfShared, RelativeUrdfsLoadTheirMeshes) {
  REQUIRE_SHARED();
  LoadOptions o;
  o.use_ros_package_path = false;
  const RobotDescription panda = load_robot(panda_dir() / "urdf/panda.relative.urdf", o);
  int meshes = 0;
  for (const CollisionShape& s : panda.geometry.shapes) {
    if (s.type != ShapeType::kMesh) continue;
    ++meshes;
    ASSERT_TRUE(s.mesh);
    EXPECT_GT(s.mesh->triangles.cols(), 0) << s.mesh->path;
  }
  EXPECT_GT(meshes, 0);
  EXPECT_NO_THROW((void)load_robot(lwr_dir() / "kuka_lwr4.relative.urdf", o));
}

TEST(UrdfShared, NominalLwrNeedsAMeshThatIsNotInTheRepository) {
  REQUIRE_SHARED();
  // kuka_lwr4.urdf loads without meshes; with meshes it names the missing convex mesh package.
  EXPECT_NO_THROW((void)load_robot(lwr_dir() / "kuka_lwr4.urdf", no_meshes()));
  LoadOptions o;
  o.use_ros_package_path = false;
  const std::string msg = load_error(lwr_dir() / "kuka_lwr4.urdf", o);
  EXPECT_NE(msg.find("kuka_lwr4.urdf:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("package 'lwr_description'"), std::string::npos) << msg;
}

class PackageDir : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::have_shared()) GTEST_SKIP() << "no shared models";
    root_ = fs::temp_directory_path() / ("extwrench_pkg_" + std::to_string(::getpid()));
    fs::create_directories(root_ / "example-robot-data/robots");
    fs::create_directory_symlink(fs::absolute(panda_dir()),
                                 root_ / "example-robot-data/robots/panda_description");
  }
  void TearDown() override {
    if (!root_.empty()) fs::remove_all(root_);
  }
  fs::path root_;
};

int loaded_meshes(const RobotDescription& r) {
  int n = 0;
  for (const CollisionShape& s : r.geometry.shapes)
    n += s.type == ShapeType::kMesh && s.mesh && s.mesh->triangles.cols() > 0;
  return n;
}

TEST_F(PackageDir, PackageUrisResolveThroughTheOption) {
  LoadOptions o;
  o.use_ros_package_path = false;
  o.package_path = {root_ / "nothing_here", root_};
  const RobotDescription r = load_robot(panda_dir() / "urdf/panda.urdf", o);
  EXPECT_GT(loaded_meshes(r), 0);
}

TEST_F(PackageDir, PackageUrisResolveThroughRosPackagePath) {
  const char* old = std::getenv("ROS_PACKAGE_PATH");
  const std::string saved = old ? old : "";
  ::setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + root_.string()).c_str(), 1);
  LoadOptions o;
  std::string err;
  int n = 0;
  try {
    n = loaded_meshes(load_robot(panda_dir() / "urdf/panda.urdf", o));
  } catch (const Error& e) {
    err = e.what();
  }
  o.use_ros_package_path = false;
  const std::string without = load_error(panda_dir() / "urdf/panda.urdf", o);
  if (old) {
    ::setenv("ROS_PACKAGE_PATH", saved.c_str(), 1);
  } else {
    ::unsetenv("ROS_PACKAGE_PATH");
  }
  EXPECT_EQ(err, "");
  EXPECT_GT(n, 0);
  EXPECT_NE(without.find("package 'example-robot-data'"), std::string::npos) << without;
}

}  // namespace
}  // namespace extwrench
