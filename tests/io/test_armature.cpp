// Armature in the files (docs/model.md "Armature"): the URDF `<dynamics armature>` extension
// read and written back, DH YAML `armature:`, estimator configurations overriding it, and bad
// values named. The dynamics it enters are checked against KDL and MuJoCo in
// tests/reference/test_locked_armature.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/io/urdf_writer.hpp"
#include "extwrench/model/model_builder.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

const fs::path kTree = fs::path(EXTWRENCH_TEST_DATA_DIR) / "robots/gripper_tree.urdf";

std::string two_joints(const std::string& dynamics) {
  return R"(<robot name="two">
  <link name="base"/>
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    )" + dynamics +
         R"(</joint>
  <joint name="j2" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><dynamics armature="2.5"/></joint>
</robot>)";
}

std::string error_of(const std::string& xml) {
  try {
    (void)load_urdf_string(xml, "two.urdf");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Armature, UrdfAttributeIsReadAndWrittenBack) {
  const Model m =
      load_urdf_string(two_joints(R"(<dynamics damping="0.1" armature="0.25"/>)"), "two.urdf")
          .model;
  ASSERT_EQ(m.nq(), 2);
  EXPECT_EQ(m.joints[1].armature, 0.25);
  EXPECT_EQ(m.joints[1].damping, 0.1);
  EXPECT_EQ(m.joints[2].armature, 2.5);
  EXPECT_TRUE(m.has_armature());
  const std::string written = write_urdf_string(m, GeometryModel{});
  EXPECT_NE(written.find("armature=\"0.25\""), std::string::npos) << written;
  const Model back = load_urdf_string(written, "back.urdf").model;
  EXPECT_EQ(back.joints[1].armature, 0.25);
  EXPECT_EQ(back.joints[2].armature, 2.5);
  // Without armature nothing is written (files of models without one are unchanged).
  Model bare = m;
  for (Joint& j : bare.joints) j.armature = 0.0;
  EXPECT_FALSE(bare.has_armature());
  EXPECT_EQ(write_urdf_string(bare, GeometryModel{}).find("armature"), std::string::npos);
}

TEST(Armature, NegativeOrNonNumericArmatureIsAnError) {
  std::string e = error_of(two_joints(R"(<dynamics armature="-0.1"/>)"));
  EXPECT_NE(
      e.find("two.urdf:6: <dynamics> of joint 'j1': attribute 'armature': must not be negative"),
      std::string::npos)
      << e;
  e = error_of(two_joints(R"(<dynamics armature="abc"/>)"));
  EXPECT_NE(e.find("attribute 'armature': expected a number, got 'abc'"), std::string::npos) << e;
  Model m = load_urdf_string(two_joints(""), "two.urdf").model;
  m.joints[1].armature = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(validate_model(m), Error);
}

TEST(Armature, ConfigurationsReplaceTheRobotFilesArmature) {
  const std::string robot = "robot: " + kTree.string() +
                            "\nlocked_joints: {finger_slide: 0, finger_hinge: 0}\n"
                            "sensor: {type: ft}\n";
  const EstimatorConfig from_file = load_estimator_config_string(robot, "c.yaml");
  EXPECT_FALSE(from_file.robot.model.has_armature());
  const EstimatorConfig c =
      load_estimator_config_string(robot + "armature: [0.3, 0.1]\n", "c.yaml");
  EXPECT_EQ(c.robot.model.joints[1].armature, 0.3);
  EXPECT_EQ(c.robot.model.joints[2].armature, 0.1);
  EXPECT_NE(to_yaml(c, fs::temp_directory_path())
                .find("armature: [0.29999999999999999, 0.10000000000000001]"),
            std::string::npos);
  try {
    (void)load_estimator_config_string(robot + "armature: [0.3, -1]\n", "c.yaml");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("c.yaml:4: armature"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace extwrench
