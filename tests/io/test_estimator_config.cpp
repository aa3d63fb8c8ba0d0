// The estimator's YAML configuration (docs/config.md): every key, the defaults, relative robot
// paths, a write/read round trip, and errors that name the file, the line and the key.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "support/error_of.hpp"
#include "support/text_files.hpp"

namespace extwrench {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

const std::filesystem::path kDir = std::filesystem::path(EXTWRENCH_TEST_DATA_DIR) / "config";

TEST(EstimatorConfig, ReadsEveryKeyOfAFullFile) {
  const EstimatorConfig c = load_estimator_config(kDir / "paper_ft.yaml");
  const EstimatorOptions& o = c.options;
  EXPECT_EQ(c.robot.model.nq(), 7);
  EXPECT_EQ(o.sensor.type, SensorType::kForceTorque);
  EXPECT_TRUE(o.sensor.X_WS.translation.isApprox(Vector3(0, 0, -0.31)));
  EXPECT_EQ(o.sensor.tare_samples, 20);
  EXPECT_EQ(o.contact.model, ContactModel::kPureForce);
  EXPECT_EQ(o.observer_gain.size(), 7);
  EXPECT_EQ(o.observer_gain[3], 120.0);
  EXPECT_EQ(o.detection.tau_min[6], 0.3);
  ASSERT_EQ(o.detection.inertial_margin.size(), 7);
  EXPECT_EQ(o.detection.inertial_margin[5], 0.05);
  EXPECT_EQ(o.detection.f_min, 4.0);
  EXPECT_EQ(o.detection.release_ratio, 0.6);
  EXPECT_EQ(o.detection.min_duration, 0.004);
  EXPECT_EQ(o.detection.sensor_release_duration, 0.002);
  EXPECT_EQ(o.acceleration, AccelerationRoute::kResidual);
  ASSERT_TRUE(o.friction.has_value());
  EXPECT_EQ(o.friction->viscous, VectorX::Constant(7, 0.1));
  EXPECT_EQ(o.friction->coulomb[5], 0.05);
  EXPECT_EQ(o.friction->smoothing_velocity, 0.002);
  ASSERT_TRUE(o.payload.has_value());
  EXPECT_EQ(c.robot.model.bodies[o.payload->body].name, "link7");
  EXPECT_EQ(o.payload->inertia.mass, 0.5);
  EXPECT_EQ(o.payload->inertia.inertia_com(2, 2), 0.0005);
  EXPECT_EQ(o.isolation.rule, IsolationRule::kGeometry);
  EXPECT_EQ(o.isolation.tolerance, 1.5);
  EXPECT_EQ(o.isolation.ambiguity_distance, 0.02);
  EXPECT_EQ(o.isolation.misfit_margin, 0.1);
  EXPECT_EQ(o.solver.max_condition, 2000.0);
  EXPECT_EQ(o.solver.rank_tolerance, 1e-6);
  EXPECT_EQ(o.uncertainty.residual_sigma.size(), 7);
  EXPECT_EQ(o.uncertainty.residual_sigma[3], 0.05);
  EXPECT_EQ(o.uncertainty.sensor_force_sigma, Vector3(0.5, 0.5, 0.8));
  EXPECT_EQ(o.uncertainty.sensor_moment_sigma, Vector3::Constant(0.05));
  EXPECT_EQ(o.uncertainty.uncertain_fraction, 0.4);
  EXPECT_EQ(o.uncertainty.uncertain_sigmas, 2.0);
}

TEST(EstimatorConfig, AFileThatIsNotAMappingSaysWhatItIs) {
  // A CSV log given as --config, or a list: once only "(top level): expected a mapping".
  struct Case {
    const char* text;
    const char* expected;
  };
  for (const Case& c :
       {Case{"t,q1,q2\n0,1,2\n",
             "c.yaml:1: (top level): expected a mapping (key: value), got the "
             "text 't,q1,q2 0,1,2'"},
        Case{"- a\n- b\n", "c.yaml:1: (top level): expected a mapping (key: value), got a list"}}) {
    const std::string msg =
        test::error_of([&] { (void)load_estimator_config_string(c.text, "c.yaml"); });
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.text << " -> " << msg;
  }
  // A DH table (read by the same YAML reader) that holds only a comment.
  const std::filesystem::path empty =
      std::filesystem::temp_directory_path() / "extwrench_empty_table.yaml";
  test::write_text(empty, "# only a comment\n");
  const std::string msg = test::error_of([&] { (void)load_robot(empty); });
  std::filesystem::remove(empty);
  EXPECT_NE(msg.find("extwrench_empty_table.yaml: (top level): expected a mapping (key: value), "
                     "got nothing: the file is empty (or only comments)"),
            std::string::npos)
      << msg;
}

TEST(EstimatorConfig, EverythingButRobotAndSensorTypeHasADefault) {
  const EstimatorConfig c = load_estimator_config(kDir / "minimal_none.yaml");
  const EstimatorOptions d;
  EXPECT_EQ(c.options.sensor.type, SensorType::kNone);
  // Without sensor.pose in the file: the model's frame 'sensor', 0.31 m below O_0 in
  // models/paper_arm.urdf (its <joint name="sensor_joint">), as `dynamics` and scenarios take it.
  EXPECT_TRUE(
      c.options.sensor.X_WS.is_approx(Pose{Matrix3::Identity(), Vector3(0, 0, -0.31)}, 1e-12));
  EXPECT_EQ(c.sensor_pose_source, "the model's frame 'sensor'");
  EXPECT_EQ(c.options.sensor.tare_samples, 0);
  EXPECT_EQ(c.options.contact.model, ContactModel::kPureForce);
  EXPECT_EQ(c.options.observer_gain, d.observer_gain);
  EXPECT_EQ(c.options.detection.tau_min, d.detection.tau_min);
  EXPECT_EQ(c.options.detection.f_min, d.detection.f_min);
  EXPECT_EQ(c.options.acceleration, AccelerationRoute::kResidual);
  EXPECT_FALSE(c.options.friction.has_value());  // the robot file's <dynamics>
  EXPECT_FALSE(c.options.payload.has_value());
  EXPECT_TRUE(c.robot.model.gravity.isApprox(Vector3(0, 0, -9.81)));
}

// A base sensor named by its frame (a URDF's ft_sensor_link), which the review found users had
// to copy by hand from `info`: the paper arm's 'sensor' (0.31 m below O_0, its URDF's
// sensor_joint), and its root link's own frame 'link0', which is not the default.
TEST(EstimatorConfig, TheSensorPoseMayBeAFrameOfTheRootLink) {
  const auto load = [](const std::string& frame) {
    return load_estimator_config_string(
        "robot: ../../../models/paper_arm.urdf\nsensor: {type: ft, frame: " + frame + "}\n",
        kDir / "frame.yaml");
  };
  const EstimatorConfig sensor = load("sensor");
  EXPECT_TRUE(
      sensor.options.sensor.X_WS.is_approx(Pose{Matrix3::Identity(), Vector3(0, 0, -0.31)}, 1e-12));
  EXPECT_EQ(sensor.sensor_pose_source, "sensor.frame 'sensor'");
  const EstimatorConfig root = load("link0");
  EXPECT_TRUE(root.options.sensor.X_WS.is_approx(Pose::identity(), 0.0));
  EXPECT_EQ(root.sensor_pose_source, "sensor.frame 'link0'");
}

TEST(EstimatorConfig, RobotPathIsRelativeToTheConfigFileAndKnownPointLinksResolveByName) {
  const EstimatorConfig c = load_estimator_config(kDir / "known_point_force.yaml");
  EXPECT_TRUE(std::filesystem::equivalent(
      c.robot_path, std::filesystem::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf"));
  EXPECT_EQ(c.options.sensor.type, SensorType::kForce);
  EXPECT_EQ(c.options.sensor.tare_samples, 100);  // tare: true
  EXPECT_EQ(c.options.contact.model, ContactModel::kKnownPoint);
  EXPECT_EQ(c.robot.model.bodies[c.options.contact.link].name, "link6");
  EXPECT_TRUE(c.options.contact.point_L.isApprox(Vector3(0, 0, 0.1)));
  EXPECT_EQ(c.options.acceleration, AccelerationRoute::kDifferentiation);
  EXPECT_EQ(c.options.differentiation_cutoff, 40.0);
  ASSERT_TRUE(c.options.friction.has_value());
  EXPECT_TRUE(c.options.friction->is_zero());
}

TEST(EstimatorConfig, GravityOfTheConfigOverridesTheRobotFile) {
  const EstimatorConfig c = load_estimator_config_string(
      "robot: ../../../models/paper_arm.urdf\ngravity: [9.81, 0, 0]\nsensor: {type: ft}\n",
      kDir / "wall.yaml");
  EXPECT_TRUE(c.robot.model.gravity.isApprox(Vector3(9.81, 0, 0)));
}

// fuzz_estimator_config's finding (tests/data/fuzz_findings/estimator_config/): a sensor roll
// of 5 rad was written with a pitch of "-0", read back as +0, so the second writing differed.
TEST(EstimatorConfig, WrittenSensorPoseIsAFixedPointOfWritingAndReading) {
  for (const char* rpy : {"[5, 0, 0]", "[0, 0, 5]", "[0, 0, 0]"}) {
    const EstimatorConfig a = load_estimator_config_string(
        std::string("robot: ../../../models/paper_arm.urdf\nsensor: {type: ft, pose: {xyz: [0, 0, "
                    "-0.31], rpy: ") +
            rpy + "}}\n",
        kDir / "pose.yaml");
    const std::string once = to_yaml(a, kDir);
    const std::string twice = to_yaml(load_estimator_config_string(once, kDir / "w.yaml"), kDir);
    EXPECT_EQ(once, twice) << "rpy " << rpy;
    EXPECT_EQ(once.find("-0,"), std::string::npos) << once;
  }
}

// A robot in a directory whose name YAML would read otherwise (": " starts a mapping, "#" after a
// space a comment, "[" a sequence): the written configuration quotes the path, and reads back.
// It was written bare, and the file did not load ("illegal map value").
TEST(EstimatorConfig, WrittenRobotPathReadsBackWhateverItsCharacters) {
  const std::string arm = test::read_text(EXTWRENCH_SOURCE_DIR "/models/paper_arm.urdf");
  for (const char* name : {"arms: v2", "lab #3", "[old]", "yes", "plain_dir-1.0"}) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "extwrench_written_robot_path" / name;
    std::filesystem::create_directories(dir);
    test::write_text(dir / "arm.urdf", arm);
    EstimatorConfig a;
    a.robot_path = dir / "arm.urdf";
    a.robot = load_robot(a.robot_path);
    a.options.sensor.type = SensorType::kNone;
    const std::string text = to_yaml(a, dir.parent_path());
    const EstimatorConfig b =
        load_estimator_config_string(text, dir.parent_path() / "written.yaml");
    EXPECT_EQ(std::filesystem::weakly_canonical(b.robot_path),
              std::filesystem::weakly_canonical(a.robot_path))
        << text;
    if (std::string(name) == "plain_dir-1.0") {
      EXPECT_NE(text.find("robot: plain_dir-1.0/arm.urdf\n"), std::string::npos) << text;
    }
  }
}

TEST(EstimatorConfig, WrittenConfigReadsBackToTheSameOptions) {
  for (const char* file : {"paper_ft.yaml", "known_point_force.yaml", "minimal_none.yaml"}) {
    const EstimatorConfig a = load_estimator_config(kDir / file);
    const std::string text = to_yaml(a, kDir);
    const EstimatorConfig b = load_estimator_config_string(text, kDir / "written.yaml");
    const EstimatorOptions &x = a.options, &y = b.options;
    EXPECT_EQ(x.sensor.type, y.sensor.type) << file;
    EXPECT_TRUE(x.sensor.X_WS.is_approx(y.sensor.X_WS, 1e-15)) << file;
    EXPECT_EQ(x.sensor.tare_samples, y.sensor.tare_samples) << file;
    EXPECT_EQ(x.contact.model, y.contact.model) << file;
    EXPECT_EQ(x.contact.link, y.contact.link) << file;
    EXPECT_EQ(x.contact.point_L, y.contact.point_L) << file;
    EXPECT_EQ(x.observer_gain.minCoeff(), y.observer_gain.minCoeff()) << file;
    EXPECT_EQ(x.observer_gain.maxCoeff(), y.observer_gain.maxCoeff()) << file;
    EXPECT_EQ(x.detection.f_min, y.detection.f_min) << file;
    EXPECT_EQ(x.detection.inertial_margin, y.detection.inertial_margin) << file;
    EXPECT_EQ(x.detection.release_ratio, y.detection.release_ratio) << file;
    EXPECT_EQ(x.detection.min_duration, y.detection.min_duration) << file;
    EXPECT_EQ(x.detection.sensor_release_duration, y.detection.sensor_release_duration) << file;
    EXPECT_EQ(x.acceleration, y.acceleration) << file;
    EXPECT_EQ(x.isolation.rule, y.isolation.rule) << file;
    EXPECT_EQ(x.isolation.tolerance, y.isolation.tolerance) << file;
    EXPECT_EQ(x.isolation.ambiguity_distance, y.isolation.ambiguity_distance) << file;
    EXPECT_EQ(x.isolation.misfit_margin, y.isolation.misfit_margin) << file;
    EXPECT_EQ(x.differentiation_cutoff, y.differentiation_cutoff) << file;
    EXPECT_EQ(x.friction.has_value(), y.friction.has_value()) << file;
    EXPECT_EQ(x.payload.has_value(), y.payload.has_value()) << file;
    EXPECT_EQ(x.solver.max_condition, y.solver.max_condition) << file;
    EXPECT_EQ(x.uncertainty.residual_sigma.minCoeff(), y.uncertainty.residual_sigma.minCoeff())
        << file;
    EXPECT_EQ(x.uncertainty.residual_sigma.maxCoeff(), y.uncertainty.residual_sigma.maxCoeff())
        << file;
    EXPECT_EQ(x.uncertainty.sensor_force_sigma, y.uncertainty.sensor_force_sigma) << file;
    EXPECT_EQ(x.uncertainty.sensor_moment_sigma, y.uncertainty.sensor_moment_sigma) << file;
    EXPECT_EQ(x.uncertainty.uncertain_fraction, y.uncertainty.uncertain_fraction) << file;
    EXPECT_EQ(x.uncertainty.uncertain_sigmas, y.uncertainty.uncertain_sigmas) << file;
    EXPECT_TRUE(a.robot.model.gravity == b.robot.model.gravity) << file;
  }
}

TEST(EstimatorConfig, MakesAWorkingEstimator) {
  const EstimatorConfig c = load_estimator_config(kDir / "paper_ft.yaml");
  ContactEstimator est = make_estimator(c);
  const VectorX z = VectorX::Zero(7);
  ASSERT_TRUE(est.reset(0.0, z, z, z).ok());
  EXPECT_TRUE(est.update(1e-3, z, z, z, Vector6::Zero()).ok());
}

struct BadConfig {
  const char* yaml;
  const char* line;  // ":<line>:" expected in the message
  const char* key;   // key named in the message
  const char* what;  // part of the explanation
};

class EstimatorConfigErrors : public ::testing::TestWithParam<BadConfig> {};

TEST_P(EstimatorConfigErrors, NameTheFileTheLineAndTheKey) {
  const BadConfig& b = GetParam();
  const std::string yaml = std::string("robot: ../../../models/paper_arm.urdf\n") + b.yaml;
  try {
    (void)load_estimator_config_string(yaml, kDir / "bad.yaml");
    FAIL() << "no error for:\n" << yaml;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_TRUE(contains(msg, "bad.yaml")) << msg;
    EXPECT_TRUE(contains(msg, b.line)) << msg;
    EXPECT_TRUE(contains(msg, b.key)) << msg;
    EXPECT_TRUE(contains(msg, b.what)) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, EstimatorConfigErrors,
    ::testing::Values(
        BadConfig{"sensor: {type: ft}\nsenser: 1\n", ":3:", "senser", "unknown key"},
        BadConfig{"sensor:\n  type: ft\n  tipe: 2\n", ":4:", "sensor.tipe", "unknown key"},
        // A key twice: YAML forbids it, yaml-cpp would read the first and drop the second.
        BadConfig{"sensor: {type: ft}\ndetection: {tau_min: 1}\ndetection: {tau_min: 2}\n",
                  ":4:", "detection", "given twice in one mapping (first at"},
        BadConfig{"sensor: {type: none, type: ft}\n", ":2:", "sensor.type", "given twice"},
        BadConfig{"sensor: {type: laser}\n", ":2:", "sensor.type",
                  "expected one of ft, force, none"},
        BadConfig{"sensor: {pose: {xyz: [0, 0, 0]}}\n", ":2:", "sensor.type", "missing"},
        BadConfig{"gravity: [0, 0]\nsensor: {type: ft}\n", ":2:", "gravity", "3 numbers"},
        BadConfig{"sensor:\n  type: ft\n  pose: {xyz: [0, a, 0]}\n", ":4:", "sensor.pose.xyz[1]",
                  "finite number"},
        BadConfig{"sensor: {type: ft, tare: -3}\n", ":2:", "sensor.tare", "whole number"},
        BadConfig{"sensor: {type: ft, frame: ft_link}\n", ":2:", "sensor.frame",
                  "'ft_link' is not a frame of robot 'paper_arm' (frames on the root link "
                  "'link0': "},
        BadConfig{"sensor: {type: ft, frame: link3}\n", ":2:", "sensor.frame",
                  "'link3' is on the moving link 'link3': a base sensor is under the root link"},
        BadConfig{"sensor: {type: ft, frame: sensor, pose: {xyz: [0, 0, 0]}}\n",
                  ":2:", "sensor.frame", "give either sensor.pose or sensor.frame, not both"},
        BadConfig{"sensor: {type: none}\nobserver:\n  gain: fast\n", ":4:", "observer.gain",
                  "finite number"},
        BadConfig{"sensor: {type: none}\nobserver:\n  gain: -5\n", ":4:", "observer.gain", "> 0"},
        BadConfig{"sensor: {type: none}\ndetection:\n  tau_min: [1, 2, 3]\n",
                  ":4:", "detection.tau_min", "7 values"},
        BadConfig{"sensor: {type: ft}\ndetection:\n  release_ratio: 1.5\n",
                  ":4:", "detection.release_ratio", "(0, 1]"},
        BadConfig{"sensor: {type: ft}\ndetection:\n  min_duration: -0.1\n",
                  ":4:", "detection.min_duration", ">= 0"},
        BadConfig{"sensor: {type: ft}\ndetection:\n  sensor_release_duration: soon\n",
                  ":4:", "detection.sensor_release_duration", "finite number"},
        BadConfig{"sensor: {type: ft}\ndetection:\n  f_min: 0\n", ":4:", "detection.f_min", "> 0"},
        BadConfig{"sensor: {type: none}\ndetection:\n  inertial_margin: -0.01\n",
                  ":4:", "detection.inertial_margin", ">= 0"},
        BadConfig{"sensor: {type: none}\ndetection:\n  inertial_margin: [0.01, 0.02]\n",
                  ":4:", "detection.inertial_margin", "7 values"},
        BadConfig{"sensor: {type: ft}\nisolation:\n  misfit_margin: -1\n",
                  ":4:", "isolation.misfit_margin", ">= 0"},
        BadConfig{"sensor: {type: ft}\ndetection:\n  f_min: inf\n", ":4:", "detection.f_min",
                  "expected a finite number, got 'inf'"},
        BadConfig{"sensor: {type: ft}\ncontact:\n  model: known_point\n  link: link99\n",
                  ":5:", "contact.link", "no link named 'link99'"},
        BadConfig{"sensor: {type: ft}\ncontact:\n  model: known_point\n", ":4:", "contact.link",
                  "missing"},
        BadConfig{"sensor: {type: ft}\ncontact: {model: guess}\n", ":3:", "contact.model",
                  "expected one of pure_force, known_point, got 'guess'"},
        BadConfig{"sensor: {type: ft}\nacceleration: integrate\n", ":3:", "acceleration",
                  "expected one of residual, differentiation, got 'integrate'"},
        BadConfig{"sensor: {type: ft}\nfriction: {viscous: [1, 2]}\n", ":3:", "friction.viscous",
                  "7 values"},
        BadConfig{"sensor: {type: ft}\nfriction: {sign: dahl, viscous: 0, coulomb: 0.2}\n",
                  ":3:", "friction", "sign: dahl needs presliding_displacement"},
        BadConfig{"sensor: {type: ft}\nfriction: {sign: tanh, viscous: 0, coulomb: 0.2,\n"
                  "  presliding_displacement: 0.002}\n",
                  ":4:", "friction.presliding_displacement", "only used with sign: dahl"},
        BadConfig{"sensor: {type: ft}\nfriction: {sign: dahl, viscous: 0, coulomb: 0.2,\n"
                  "  presliding_displacement: [0.002, 0, 0.002, 0.002, 0.002, 0.002, 0.002]}\n",
                  ":4:", "friction.presliding_displacement[1]", "> 0"},
        BadConfig{"sensor: {type: ft}\nfriction: {sign: dahl, viscous: 0, coulomb: 0.2,\n"
                  "  presliding_displacement: 0.002, smoothing_velocity: 0.01}\n",
                  ":4:", "friction.smoothing_velocity", "not used with sign: dahl"},
        BadConfig{"sensor: {type: ft}\npayload: {link: link7, mass: -1}\n", ":3:", "payload.mass",
                  ">= 0"},
        BadConfig{
            "sensor: {type: ft}\npayload: {link: link7, mass: 1, inertia: [1, 0, 0, 1, 0, -1]}\n",
            ":3:", "payload.inertia", "payload"},
        BadConfig{"sensor: {type: ft}\nsolver: {max_condition: 0.5}\n",
                  ":3:", "solver.max_condition", "> 1"},
        BadConfig{"sensor: {type: ft}\nuncertainty: {residual_sigma: [1, 2]}\n",
                  ":3:", "uncertainty.residual_sigma", "7 values"},
        BadConfig{"sensor: {type: ft}\nuncertainty: {sensor_force_sigma: -0.5}\n",
                  ":3:", "uncertainty.sensor_force_sigma", ">= 0"},
        BadConfig{"sensor: {type: ft}\nuncertainty: {uncertain_fraction: 0}\n",
                  ":3:", "uncertainty.uncertain_fraction", "> 0"},
        BadConfig{"sensor: {type: ft}\nuncertainty: {sigma: 1}\n", ":3:", "uncertainty.sigma",
                  "unknown key"},
        BadConfig{"sensor: {type: ft}\ndrift: {time_constant: 0}\n", ":3:", "drift.time_constant",
                  "> 0"},
        BadConfig{"sensor: {type: ft}\ndrift: {max_rate: 1}\n", ":3:", "drift.max_rate",
                  "unknown key"},
        BadConfig{"sensor: [ft\n", ":", "YAML", "syntax"}));

// drift: true takes the defaults; a mapping sets them; to_yaml writes them back; absent = off.
TEST(EstimatorConfig, DriftTrackingIsOptInAndRoundTrips) {
  const std::string robot = "robot: ../../../models/paper_arm.urdf\nsensor: {type: ft}\n";
  EXPECT_FALSE(load_estimator_config_string(robot, kDir / "a.yaml").options.drift);
  const EstimatorConfig on = load_estimator_config_string(robot + "drift: true\n", kDir / "b.yaml");
  ASSERT_TRUE(on.options.drift);
  EXPECT_EQ(on.options.drift->time_constant, DriftOptions{}.time_constant);
  const EstimatorConfig set = load_estimator_config_string(
      robot +
          "drift: {time_constant: 12, max_torque_rate: 0.2, max_force_rate: 0.3, "
          "max_moment_rate: 0.04}\n",
      kDir / "c.yaml");
  ASSERT_TRUE(set.options.drift);
  const EstimatorConfig back = load_estimator_config_string(to_yaml(set, kDir), kDir / "d.yaml");
  ASSERT_TRUE(back.options.drift);
  EXPECT_EQ(back.options.drift->time_constant, 12.0);
  EXPECT_EQ(back.options.drift->max_torque_rate, 0.2);
  EXPECT_EQ(back.options.drift->max_force_rate, 0.3);
  EXPECT_EQ(back.options.drift->max_moment_rate, 0.04);
  EXPECT_FALSE(
      load_estimator_config_string(robot + "drift: false\n", kDir / "e.yaml").options.drift);
}

TEST(EstimatorConfig, MissingRobotOrRobotFileIsAnErrorNamingTheKey) {
  try {
    (void)load_estimator_config_string("sensor: {type: ft}\n", kDir / "norobot.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_TRUE(contains(std::string(e.what()), "norobot.yaml"));
    EXPECT_TRUE(contains(std::string(e.what()), "robot: missing"));
  }
  try {
    (void)load_estimator_config_string("robot: nowhere.urdf\nsensor: {type: ft}\n",
                                       kDir / "lost.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_TRUE(contains(std::string(e.what()), "lost.yaml:1: robot: cannot load"));
  }
  EXPECT_THROW((void)load_estimator_config(kDir / "does_not_exist.yaml"), Error);
}

TEST(EstimatorConfig, ARobotFileGivenForTheConfigurationIsNamedAsSuch) {
  // `extwrench estimate --config models/paper_arm.urdf`: once "YAML syntax error: illegal map
  // value" on line 3 of the URDF.
  const std::filesystem::path urdf =
      std::filesystem::path(EXTWRENCH_SOURCE_DIR) / "models" / "paper_arm.urdf";
  try {
    (void)load_estimator_config(urdf);
    FAIL();
  } catch (const Error& e) {
    EXPECT_TRUE(contains(std::string(e.what()),
                         urdf.string() + ":1: this is XML (a URDF or MJCF robot file?), but a "
                                         "configuration is YAML, which names the robot file "
                                         "under 'robot:'"))
        << e.what();
  }
}

}  // namespace
}  // namespace extwrench
