// Simulation scenarios (YAML, docs/simulation.md): the file format. Running them is
// app/scenario_run.hpp (`extwrench simulate`).
//
// A scenario names the robot, the desired trajectory and the controller, the forces, the sensor
// models, the seeds and the dynamic-parameter error, and one or more estimator configurations
// ("schemes", in the format of docs/config.md, without `robot`: they use the perturbed model).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "extwrench/io/robot_loader.hpp"
#include "extwrench/sim/simulator.hpp"

namespace extwrench {

struct SchemeSpec {
  std::string name;
  std::string yaml;  ///< the scheme's configuration as YAML text, without `robot`
  int line = 0;      ///< where it is defined in the scenario
};

struct MetricTarget {
  std::string scheme;
  std::string metric;  ///< force_rms | force_rms_outside | line_rms | right_link
  double value = 0.0;  ///< upper bound (right_link: lower bound, percent)
  int line = 0;
};

struct Scenario {
  std::filesystem::path source;
  std::filesystem::path robot_path;
  RobotDescription robot;
  /// How `robot` was loaded (package path, locked joints with the scenario's own): what a
  /// configuration naming the same robot file needs to load the same model.
  LoadOptions robot_options;
  std::vector<std::uint64_t> seeds{1};
  double model_error = 0.01;  ///< ± fraction of every dynamic parameter (docs/simulation.md)
  sim::SimulationConfig simulation;  ///< forces, sensors, duration, steps (noise seed per run)
  sim::SinusoidalTrajectory trajectory;
  sim::PidGains gains;
  double controller_omega = 0.0;  ///< when the gains come from `controller.omega`
  bool log_velocity = true;       ///< write dq1..dqn (else estimate differentiates q)
  // Metrics
  double metrics_from = 0.2;  ///< [s] start of every window (after the residual's transient)
  std::vector<std::pair<double, double>> metrics_exclude;
  double singularity_half_width = 0.0;  ///< > 0: a second window excluding ± this around each
                                        ///< crossing of cond(J of O_l) above the threshold
  double singularity_threshold = 1e3;   ///< cond(J of O_l) above this is a crossing
  std::string
      singularity_link;  ///< link l whose cond(J of O_l) is tracked (default: first force's)
  bool surface_metrics = false;
  /// metrics.targets: per scheme, the metric (force_rms, force_rms_outside, line_rms,
  /// right_link [%]) and the value the scenario states it should reach (docs/simulation.md).
  std::vector<MetricTarget> targets;
  bool figures = true;
  std::vector<SchemeSpec> schemes;
};

/// Reads a scenario and loads its robot. Throws extwrench::Error naming file, line and key
/// (unknown keys, wrong types, sizes that do not match the robot, values out of range).
[[nodiscard]] Scenario load_scenario(const std::filesystem::path& path,
                                     const LoadOptions& robot_options = {});

/// The scheme's estimator configuration file (docs/config.md) for a run of the scenario: the
/// scheme's own keys, plus `robot: ../model_estimator.urdf` (the perturbed model written next to
/// the log), gravity, and the simulated sensor's pose when the scheme does not give one.
[[nodiscard]] std::string scheme_config_yaml(const Scenario& scenario, const SchemeSpec& scheme);

}  // namespace extwrench
