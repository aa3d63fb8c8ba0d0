// The estimator's configuration file (YAML; documented in docs/config.md):
// clang-format off
//
//   robot: ../models/paper_arm.urdf   # URDF or DH YAML, relative to this file (required)
//   locked_joints: {finger_1: 0.02}   # joints held fixed [rad | m] (a tree's branches)
//   gravity: [0, 0, -9.81]            # [m/s^2], world frame; default: the robot file's
//   sensor:
//     type: ft                        # ft | force | none (required)
//     pose: {xyz: [0, 0, 0], rpy: [0, 0, 0]}   # sensor frame in the robot's root frame;
//                                     # default: the model's 'sensor' frame, else the root's
//     tare: false                     # false | true (100 samples) | N samples
//   contact:
//     model: pure_force               # pure_force | known_point
//     link: link6                     # known_point only
//     point: [0, 0, 0.1]              # known_point only, link frame [m]
//   observer: {gain: 100}             # K [1/s]: number or list of n
//   detection: {tau_min: 1.0, f_min: 5.0, release_ratio: 0.5, min_duration: 0.005}
//   acceleration: residual            # residual | differentiation | {route: ..., cutoff: 50}
//   friction: model                   # model | none | {viscous, coulomb, smoothing_velocity}
//   payload: {link: link7, mass: 0.5, com: [0, 0, 0.05], inertia: [ixx, ixy, ixz, iyy, iyz, izz]}
//   solver: {max_condition: 1000, rank_tolerance: 1e-6}
//
// clang-format on
// Every key but robot and sensor.type has a default. Unknown keys, wrong types and values out of
// range throw extwrench::Error naming the file, the line and the key.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/robot_loader.hpp"

namespace extwrench {

/// A configuration file, interpreted against the robot it names.
struct EstimatorConfig {
  std::filesystem::path source;      ///< the configuration file (or the name given to the string)
  std::filesystem::path robot_path;  ///< resolved path of the robot file
  RobotDescription robot;            ///< loaded robot (gravity from the config applied)
  /// Joints locked when loading it (the file's locked_joints and LoadOptions'), for to_yaml.
  std::map<std::string, double> locked_joints;
  /// The chain chosen in an MJCF scene (the file's root_body, tip_body, or LoadOptions'), for
  /// to_yaml; empty when not chosen.
  std::string root_body, tip_body;
  EstimatorOptions options;  ///< link names resolved to body indices, sizes checked
  /// Where options.sensor.X_WS came from: "sensor.pose" when the file gives it, else the rule
  /// of default_sensor_pose() in words (printed at the start of a replay).
  std::string sensor_pose_source;
  /// The calibration file the configuration includes (`calibration:`, resolved); empty: none.
  std::filesystem::path calibration_path;
};

/// Which rule default_sensor_pose() (estimation/base_sensor.hpp) applies to `model`, in words
/// for messages: "the model's frame 'sensor'" or "the root link's origin ('base'), aligned with
/// it" (with the reason when a 'sensor' frame sits on a moving body).
[[nodiscard]] std::string describe_default_sensor_pose(const Model& model);

/// Reads a configuration file and loads its robot. Throws extwrench::Error naming file, line, key.
[[nodiscard]] EstimatorConfig load_estimator_config(const std::filesystem::path& path,
                                                    const LoadOptions& robot_options = {});

/// The same from a YAML string; `name` stands for the file in messages and its directory
/// resolves the robot path.
[[nodiscard]] EstimatorConfig load_estimator_config_string(const std::string& yaml,
                                                           const std::filesystem::path& name,
                                                           const LoadOptions& robot_options = {});

/// The configured estimator (model and collision geometry copied from config.robot).
[[nodiscard]] ContactEstimator make_estimator(const EstimatorConfig& config);

/// The options written back as a configuration file (robot path as given, made relative to
/// `directory` when possible; an empty `directory` keeps it). Loading the result gives the same
/// options.
[[nodiscard]] std::string to_yaml(const EstimatorConfig& config,
                                  const std::filesystem::path& directory);

}  // namespace extwrench
