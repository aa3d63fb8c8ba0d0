// A property suite spanning several sources, so it keeps its own name (docs/layout.md, Tests).
// Every file in tests/data/malformed/ must be rejected with a message that starts with
// "<path>:<line>:" and names the element/key and field (table-driven).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/io/robot_loader.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

struct Expected {
  int line;
  std::vector<std::string> fragments;
};

const std::map<std::string, Expected>& cases() {
  static const std::map<std::string, Expected> kCases = {
      // ---- URDF
      {"mass_not_a_number.urdf",
       {11, {"<mass> of link 'arm'", "attribute 'value'", "expected a number, got 'abc'"}}},
      {"mass_trailing_garbage.urdf",
       {11, {"<mass> of link 'arm'", "attribute 'value'", "got '1.0x'"}}},
      {"mass_empty.urdf",
       {11, {"<mass> of link 'arm'", "attribute 'value': expected a number, got ''"}}},
      {"mass_missing_value.urdf", {11, {"<mass> of link 'arm'", "attribute 'value': missing"}}},
      {"mass_negative.urdf",
       {11, {"<mass> of link 'arm'", "attribute 'value': must not be negative, got '-1'"}}},
      {"inertia_not_a_number.urdf",
       {12, {"<inertia> of link 'arm'", "attribute 'ixx'", "got 'abc'"}}},
      {"inertia_missing_iyz.urdf", {12, {"<inertia> of link 'arm'", "attribute 'iyz': missing"}}},
      // ixx, iyy, izz are physical, ixy is not: the message points at the products.
      {"inertia_not_psd.urdf",
       {12,
        {"<inertia> of link 'arm'", "inertia: not positive semi-definite",
         "ixx, iyy, izz alone would be physical: are the products ixy, ixz, iyz (0.5, 0, 0) "
         "placeholders?"}}},
      {"inertia_triangle.urdf",
       {12, {"link 'arm'", "inertia: principal moments violate the triangle inequality"}}},
      {"inertia_nan.urdf", {12, {"<inertia> of link 'arm'", "attribute 'ixx'", "got 'nan'"}}},
      {"inertial_missing_inertia.urdf",
       {9, {"<inertial> of link 'arm'", "missing element <inertia>"}}},
      {"origin_two_numbers.urdf",
       {10, {"<origin> of link 'arm'", "attribute 'xyz'", "expected 3 numbers, got '0 0'"}}},
      {"joint_origin_bad_rpy.urdf",
       {19, {"<origin> of joint 'j1'", "attribute 'rpy'", "got '0 0 x'"}}},
      {"axis_zero.urdf", {20, {"<axis> of joint 'j1'", "attribute 'xyz'", "must not be zero"}}},
      {"limit_lower_above_upper.urdf",
       {21, {"<limit> of joint 'j1'", "'lower' > 'upper'", "('2' > '1')"}}},
      // Only one bound given, the other defaulting to 0 (issue 14: the message once appended
      // the missing attribute, a null pointer, and crashed).
      {"limit_lower_only_positive.urdf",
       {21, {"<limit> of joint 'j1'", "'lower' > 'upper' ('1' > 0 (missing, default))"}}},
      {"limit_upper_only_negative.urdf",
       {21, {"<limit> of joint 'j1'", "'lower' > 'upper' (0 (missing, default) > '-1')"}}},
      {"limit_missing.urdf", {16, {"<joint> of joint 'j1'", "missing element <limit>"}}},
      {"limit_missing_effort.urdf", {21, {"<limit> of joint 'j1'", "attribute 'effort': missing"}}},
      {"limit_negative_velocity.urdf",
       {21, {"<limit> of joint 'j1'", "attribute 'velocity': must not be negative"}}},
      {"joint_type_unknown.urdf",
       {16, {"joint 'j1'", "attribute 'type'", "unknown joint type 'ball'"}}},
      {"joint_type_floating.urdf",
       {16, {"joint 'j1'", "attribute 'type'", "unsupported joint type 'floating'"}}},
      {"joint_parent_unknown.urdf", {16, {"joint 'j1'", "parent: no link named 'nope'"}}},
      {"joint_child_missing.urdf", {16, {"joint 'j1'", "missing element <child>"}}},
      {"link_duplicate.urdf", {8, {"link 'base'", "duplicate link name"}}},
      {"link_two_parents.urdf",
       {23, {"joint 'j2'", "child: link 'arm' already has a parent joint 'j1'"}}},
      {"joint_cycle.urdf", {23, {"joint 'j2'", "closes a cycle of links"}}},
      {"link_two_roots.urdf", {23, {"link 'island'", "more than one root link"}}},
      {"geometry_unknown.urdf", {14, {"<cone> of link 'arm'", "unknown geometry <cone>"}}},
      {"sphere_negative_radius.urdf",
       {14, {"<sphere> of link 'arm'", "attribute 'radius': must be positive, got '-0.05'"}}},
      {"capsule_missing_length.urdf",
       {14, {"<capsule> of link 'arm'", "attribute 'length': missing"}}},
      {"mesh_missing_filename.urdf",
       {14, {"<mesh> of link 'arm'", "attribute 'filename': missing"}}},
      {"mesh_file_not_found.urdf",
       {14, {"<mesh> of link 'arm'", "attribute 'filename'", "does_not_exist.stl", "not found"}}},
      {"link_missing_name.urdf", {8, {"<link>", "attribute 'name': missing"}}},
      {"not_well_formed.urdf", {2, {"not well-formed XML"}}},
      // Misspelt elements were skipped: the joint at its parent's origin, the link massless.
      {"joint_origin_misspelt.urdf",
       {19,
        {"<orgin> of joint 'j1'", "unknown element <orgin> in <joint>", "did you mean <origin>?"}}},
      {"link_inertial_misspelt.urdf",
       {9,
        {"<inertal> of link 'arm'", "unknown element <inertal> in <link>",
         "did you mean <inertial>?"}}},
      // A .urdf.xacro loaded as it is lost its gripper without a word (a review's).
      {"xacro_macro_unexpanded.urdf",
       {3, {"<xacro:include>", "a xacro macro", "xacro robot.urdf.xacro > robot.urdf"}}},
      {"root_not_robot.urdf",
       {2, {"the root element must be <robot> (URDF) or <mujoco> (MJCF), got <model>"}}},
      {"massless_leaf.urdf",
       {11, {"joint 'j1'", "link 'arm'", "mass matrix is not positive definite"}}},
      // ---- MJCF in a program without extwrench::mujoco (tests/reference reads it)
      {"mjcf_without_mujoco.xml",
       {2, {"the root element is <mujoco>", "MJCF needs extwrench built with MuJoCo"}}},
      // ---- DH YAML
      {"convention_missing.yaml", {1, {"convention: missing"}}},
      {"convention_unknown.yaml",
       {2, {"convention:", "expected one of standard, modified, got 'dh'"}}},
      {"alpha_not_a_number.yaml",
       {11, {"joints[0].alpha:", "expected a finite number (or pi expression), got 'abc'"}}},
      {"d_missing.yaml", {8, {"joints[0].d: missing"}}},
      {"mass_not_a_number.yaml", {16, {"joints[0].link.mass:", "got 'heavy'"}}},
      {"mass_negative.yaml", {16, {"joints[0].link.mass:", "expected a value >= 0 [kg], got -2"}}},
      {"inertia_five_entries.yaml", {18, {"joints[0].link.inertia:", "expected 6 numbers"}}},
      {"inertia_not_psd.yaml",
       {18, {"joints[0].link.inertia:", "link 'l1'", "not positive semi-definite"}}},
      {"inertia_not_symmetric.yaml",
       {18, {"joints[0].link.inertia:", "link 'l1'", "not symmetric"}}},
      {"com_two_numbers.yaml", {17, {"joints[0].link.com:", "expected a list of 3 numbers"}}},
      {"unknown_key.yaml", {12, {"joints[0].dd:", "unknown key"}}},
      {"joint_type_unknown.yaml", {9, {"joints[0].type:", "got 'spherical'"}}},
      {"lower_above_upper.yaml", {14, {"joints[0].lower:", "lower > upper"}}},
      {"shape_unknown.yaml",
       {20,
        {"joints[0].link.collision[0].type:",
         "expected one of sphere, box, cylinder, capsule, mesh, got 'cone'"}}},
      {"radius_negative.yaml",
       {20, {"joints[0].link.collision[0].radius:", "expected a value > 0 [m]"}}},
      {"link_missing.yaml", {8, {"joints[0].link: missing"}}},
      {"link_duplicate_name.yaml", {15, {"link 'link0'", "duplicate link name"}}},
      {"frame_unknown_link.yaml", {22, {"frames[0].link:", "no link named 'nope'"}}},
      {"gravity_two_numbers.yaml", {3, {"gravity:", "expected a list of 3 numbers"}}},
      {"joints_empty.yaml", {4, {"joints:", "expected a non-empty list"}}},
      {"not_yaml.yaml", {4, {"YAML syntax error"}}},
  };
  return kCases;
}

fs::path malformed_dir() { return fs::path(EXTWRENCH_TEST_DATA_DIR) / "malformed"; }

TEST(MalformedFiles, EveryFileIsInTheTableAndThereAreEnough) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(malformed_dir())) {
    EXPECT_TRUE(cases().count(e.path().filename().string()))
        << e.path().filename() << " has no expectation";
    ++n;
  }
  EXPECT_GE(n, 30);
  EXPECT_EQ(n, static_cast<int>(cases().size()));
}

TEST(MalformedFiles, AreRejectedNamingFileLineElementAndField) {
  LoadOptions options;
  options.use_ros_package_path = false;
  options.load_meshes = true;
  for (const auto& [file, expected] : cases()) {
    const fs::path path = malformed_dir() / file;
    std::string msg;
    try {
      (void)load_robot(path, options);
    } catch (const Error& e) {
      msg = e.what();
    }
    ASSERT_FALSE(msg.empty()) << file << " was accepted";
    const std::string where = path.string() + ":" + std::to_string(expected.line) + ":";
    EXPECT_EQ(msg.rfind(where, 0), 0u)
        << file << ": expected to start with '" << where << "', got: " << msg;
    for (const std::string& f : expected.fragments) {
      EXPECT_NE(msg.find(f), std::string::npos) << file << ": expected '" << f << "' in: " << msg;
    }
  }
}

}  // namespace
}  // namespace extwrench
