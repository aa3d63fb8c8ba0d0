// Malformed and unsupported MJCF files: each gets an extwrench::Error naming the file and the
// element (MuJoCo's element and line, or our body/joint/geom), never a crash; and load_robot
// reads MJCF once the reader is registered.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <fstream>
#include <string>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "support/scratch_dir.hpp"

namespace extwrench {
namespace {

// Succeeds when `text` contains every one of `parts`, else says which is missing.
::testing::AssertionResult has_all(const std::string& text,
                                   std::initializer_list<std::string> parts) {
  for (const std::string& part : parts) {
    if (text.find(part) == std::string::npos)
      return ::testing::AssertionFailure() << "'" << part << "' is not in: " << text;
  }
  return ::testing::AssertionSuccess();
}

class MjcfMalformed : public test::ScratchDirTest {
 protected:
  MjcfMalformed() : ScratchDirTest("mjcf_malformed") {}

  std::string write(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }

  // The message of the Error load_mjcf throws (the test fails if none is thrown).
  static std::string error_of(const std::string& path, const LoadOptions& options = {}) {
    try {
      (void)mujoco::load_mjcf(path, options);
    } catch (const Error& e) {
      return e.what();
    }
    ADD_FAILURE() << path << " loaded without an error";
    return "";
  }
};

LoadOptions chain(const std::string& root, const std::string& tip = "") {
  LoadOptions options;
  options.root_body = root;
  options.tip_body = tip;
  return options;
}

// A one-joint arm; `extra` goes inside the moving body, `joint` is its joint element.
std::string arm(const std::string& joint = "<joint name=\"j1\" axis=\"0 0 1\"/>",
                const std::string& extra = "") {
  return "<mujoco model=\"m\">\n<worldbody>\n<body name=\"base\">\n"
         "<inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"0.1 0.1 0.1\"/>\n"
         "<body name=\"link1\" pos=\"0 0 0.1\">\n" +
         joint + "\n<inertial pos=\"0 0 0.1\" mass=\"1\" diaginertia=\"0.01 0.01 0.01\"/>\n" +
         extra + "\n</body>\n</body>\n</worldbody>\n</mujoco>\n";
}

TEST_F(MjcfMalformed, AWellFormedArmLoads) {
  const RobotDescription robot = mujoco::load_mjcf(write("ok.xml", arm()));
  EXPECT_EQ(robot.model.nq(), 1);
  EXPECT_EQ(robot.model.bodies[0].name, "base");
}

TEST_F(MjcfMalformed, NotXmlNamesTheFileAndLine) {
  const std::string path = write("broken.xml", "<mujoco>\n<worldbody>\n<body name=\"a\">\n");
  EXPECT_TRUE(has_all(error_of(path), {path, "MuJoCo rejects", "XML"}));
}

TEST_F(MjcfMalformed, UnknownElementNamesTheElementAndLine) {
  const std::string path = write("unknown.xml", arm("<joint name=\"j1\"/>", "<bogus/>"));
  EXPECT_TRUE(has_all(error_of(path), {path, "bogus", "line"}));
}

// The MuJoCo Menagerie's current Panda is written for MuJoCo >= 2.3.3: on Debian's 2.2.2 its
// integrator="implicitfast" was "invalid keyword" without a word of why.
TEST_F(MjcfMalformed, AWordOfANewerMujocoSaysSo) {
  const std::string keyword =
      write("newer.xml", "<mujoco model=\"m\">\n<option integrator=\"implicitfast\"/>\n" +
                             arm().substr(std::string("<mujoco model=\"m\">\n").size()));
  EXPECT_TRUE(has_all(error_of(keyword), {keyword, "invalid keyword", "line 2",
                                          std::string("this MuJoCo is ") + mj_versionString(),
                                          "newer one", "docs/mujoco.md"}));
  const std::string attribute =
      write("kv.xml", arm("<joint name=\"j1\"/>", "<geom size=\"0.05\" kv=\"3\"/>"));
  EXPECT_TRUE(has_all(error_of(attribute), {attribute, "'kv'", "newer one"}));
  // A malformed file that no MuJoCo reads gets no such hint.
  const std::string broken = write("cut.xml", "<mujoco>\n<worldbody>\n<body name=\"a\">\n");
  EXPECT_EQ(error_of(broken).find("newer one"), std::string::npos);
}

TEST_F(MjcfMalformed, BadNumberNamesTheAttribute) {
  const std::string path = write("number.xml", arm("<joint name=\"j1\" axis=\"0 0 abc\"/>"));
  EXPECT_TRUE(has_all(error_of(path), {path, "joint", "line"}));
}

TEST_F(MjcfMalformed, MissingMeshFileNamesTheMesh) {
  const std::string path =
      write("mesh.xml",
            "<mujoco><asset><mesh name=\"gone\" file=\"gone.stl\"/></asset><worldbody>"
            "<body name=\"base\"><geom type=\"mesh\" mesh=\"gone\"/></body></worldbody></mujoco>");
  EXPECT_TRUE(has_all(error_of(path), {path, "gone.stl"}));
}

TEST_F(MjcfMalformed, BallJointNamesTheJointAndBody) {
  const std::string path = write("ball.xml", arm("<joint name=\"wrist\" type=\"ball\"/>"));
  EXPECT_TRUE(has_all(error_of(path), {path, "joint 'wrist' of body 'link1'", "ball"}));
}

TEST_F(MjcfMalformed, FloatingRobotIsRefused) {
  const std::string path = write(
      "free.xml",
      "<mujoco><worldbody><body name=\"drone\"><freejoint name=\"float\"/><geom size=\"0.1\"/>"
      "<body name=\"arm\"><joint name=\"j\"/><geom size=\"0.05\"/></body></body></worldbody>"
      "</mujoco>");
  EXPECT_TRUE(has_all(error_of(path, chain("drone")), {path, "body 'drone'", "free"}));
}

TEST_F(MjcfMalformed, JointSpringIsRefused) {
  const std::string path = write("spring.xml", arm("<joint name=\"j1\" stiffness=\"10\"/>"));
  EXPECT_TRUE(has_all(error_of(path), {path, "joint 'j1' of body 'link1'", "stiffness"}));
}

TEST_F(MjcfMalformed, PlaneOnTheRobotNamesTheGeom) {
  // MuJoCo allows planes on static bodies only: the root link is one.
  std::string text = arm();
  text.insert(text.find("<body name=\"link1\""),
              "<geom name=\"wall\" type=\"plane\" size=\"1 1 1\"/>\n");
  const std::string path = write("plane.xml", text);
  EXPECT_TRUE(has_all(error_of(path), {path, "geom 'wall' of body 'base'", "plane"}));
}

TEST_F(MjcfMalformed, SceneWithTwoRobotsAsksForTheRoot) {
  const std::string one = arm();
  std::string two = one;
  two.insert(two.find("</worldbody>"),
             "<body name=\"other\"><geom size=\"0.1\"/><body name=\"o1\"><joint name=\"oj\"/>"
             "<geom size=\"0.1\"/></body></body>\n");
  const std::string path = write("two.xml", two);
  EXPECT_TRUE(has_all(error_of(path), {path, "'base', 'other'", "root_body"}));
  const RobotDescription robot = mujoco::load_mjcf(path, chain("other"));
  EXPECT_EQ(robot.model.bodies[0].name, "other");
  EXPECT_EQ(robot.model.joints[1].name, "oj");
}

TEST_F(MjcfMalformed, WorldAsRootKeepsEveryTopLevelBodyButNotTheFloor) {
  std::string text = arm();
  text.insert(text.find("<body name=\"base\""),
              "<geom name=\"floor\" type=\"plane\" size=\"1 1 1\"/>\n");
  const RobotDescription robot = mujoco::load_mjcf(write("world.xml", text), chain("world"));
  EXPECT_EQ(robot.model.bodies[0].name, "world");
  EXPECT_EQ(robot.model.nq(), 1);
  EXPECT_TRUE(robot.geometry.shapes.empty());
}

// A hand welded to the tip moves with it: kept, with its mass (the review's Panda lost its
// 0.73 kg hand with --tip-body link7); a finger on a slide joint beyond it is dropped.
TEST_F(MjcfMalformed, TheTipKeepsWhatIsWeldedToIt) {
  const std::string hand =
      "<body name=\"hand\" pos=\"0 0 0.2\"><inertial pos=\"0 0 0.05\" mass=\"0.7\" "
      "diaginertia=\"0.002 0.002 0.002\"/>\n<body name=\"finger\"><joint name=\"slide\" "
      "type=\"slide\" axis=\"0 1 0\"/><inertial pos=\"0 0 0.1\" mass=\"0.1\" "
      "diaginertia=\"1e-4 1e-4 1e-4\"/></body>\n</body>";
  const std::string path = write("hand.xml", arm("<joint name=\"j1\" axis=\"0 0 1\"/>", hand));
  const RobotDescription robot = mujoco::load_mjcf(path, chain("", "link1"));
  EXPECT_EQ(robot.model.nq(), 1);
  double total = 0.0;
  for (const Body& b : robot.model.bodies) total += b.inertia.mass;
  EXPECT_DOUBLE_EQ(total, 1.0 + 1.0 + 0.7);          // base, link1, the hand; not the finger
  EXPECT_EQ(mujoco::load_mjcf(path).model.nq(), 2);  // without a tip: the whole tree
}

TEST_F(MjcfMalformed, UnknownRootOrTipNamesTheOption) {
  const std::string path = write("arm.xml", arm());
  EXPECT_TRUE(has_all(error_of(path, chain("nope")), {path, "root_body 'nope'", "'base'"}));
  EXPECT_TRUE(has_all(error_of(path, chain("", "nope")), {path, "tip_body 'nope'"}));
  EXPECT_TRUE(
      has_all(error_of(path, chain("link1", "base")), {path, "body 'base'", "not in the subtree"}));
}

TEST_F(MjcfMalformed, TipBodyKeepsOneChainOfATree) {
  const std::string tree =
      arm("<joint name=\"j1\"/>",
          "<body name=\"left\"><joint name=\"jl\"/><geom size=\"0.02\"/></body>"
          "<body name=\"right\"><joint name=\"jr\"/><geom size=\"0.02\"/></body>");
  const std::string path = write("tree.xml", tree);
  EXPECT_FALSE(mujoco::load_mjcf(path).model.is_serial_chain());
  const RobotDescription one_chain = mujoco::load_mjcf(path, chain("", "right"));
  EXPECT_TRUE(one_chain.model.is_serial_chain());
  EXPECT_EQ(one_chain.model.nq(), 2);
  EXPECT_FALSE(one_chain.model.find_body("left").has_value());
}

TEST_F(MjcfMalformed, UnknownLockedJointIsTheBuildersError) {
  const std::string path = write("arm.xml", arm());
  LoadOptions options;
  options.locked_joints["nope"] = 0.0;
  EXPECT_TRUE(has_all(error_of(path, options), {"nope"}));
}

TEST_F(MjcfMalformed, DirectoryAndMissingFileAreInputErrors) {
  EXPECT_TRUE(has_all(error_of(dir_.string()), {dir_.string()}));
  EXPECT_TRUE(has_all(error_of((dir_ / "absent.xml").string()), {"absent.xml"}));
}

// A scene's chain chosen in an estimator configuration (root_body, tip_body), which the loader's
// message named before the keys existed; --root-body (LoadOptions) wins; written back by
// to_yaml.
TEST_F(MjcfMalformed, AConfigurationChoosesTheChainOfAScene) {
  std::string two = arm();
  two.insert(two.find("</worldbody>"),
             "<body name=\"other\"><geom size=\"0.1\"/><body name=\"o1\"><joint name=\"oj\"/>"
             "<geom size=\"0.1\"/></body></body>\n");
  write("two.xml", two);
  const std::string config =
      write("two.yaml", "robot: two.xml\nroot_body: other\nsensor: {type: none}\n");
  mujoco::register_mjcf_loader();
  const EstimatorConfig c = load_estimator_config(config);
  EXPECT_EQ(c.robot.model.bodies[0].name, "other");
  EXPECT_EQ(c.robot.model.joints[1].name, "oj");
  EXPECT_NE(to_yaml(c, dir_).find("root_body: other\n"), std::string::npos) << to_yaml(c, dir_);
  LoadOptions command_line;
  command_line.root_body = "base";
  EXPECT_EQ(load_estimator_config(config, command_line).robot.model.joints[1].name, "j1");
  // Without the key: the scene's two robots, and the message names the key.
  write("none.yaml", "robot: two.xml\nsensor: {type: none}\n");
  try {
    (void)load_estimator_config(dir_ / "none.yaml");
    ADD_FAILURE() << "a scene with two robots loaded without a root";
  } catch (const Error& e) {
    EXPECT_TRUE(has_all(e.what(), {"none.yaml", "root_body"}));
  }
  set_mjcf_loader(nullptr);
}

TEST_F(MjcfMalformed, LoadRobotReadsMjcfOnceRegistered) {
  const std::string path = write("arm.xml", arm());
  mujoco::register_mjcf_loader();
  EXPECT_EQ(load_robot(path).model.nq(), 1);
  set_mjcf_loader(nullptr);
  try {
    (void)load_robot(path);
    ADD_FAILURE() << "MJCF loaded without a reader";
  } catch (const Error& e) {
    EXPECT_TRUE(has_all(std::string(e.what()), {path, "MJCF needs extwrench"}));
  }
}

}  // namespace
}  // namespace extwrench
