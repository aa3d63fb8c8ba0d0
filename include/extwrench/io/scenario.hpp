// Simulation scenarios (YAML, docs/simulation.md) and running them: `extwrench simulate`.
//
// A scenario names the robot, the desired trajectory and the controller, the forces, the sensor
// models, the seeds and the dynamic-parameter error, and one or more estimator configurations
// ("schemes", in the format of docs/config.md, without `robot`: they use the perturbed model).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "extwrench/io/replay.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/sim/simulator.hpp"

namespace extwrench {

struct SchemeSpec {
  std::string name;
  std::string yaml;  ///< the scheme's configuration as YAML text, without `robot`
  int line = 0;      ///< where it is defined in the scenario
};

struct Scenario {
  std::filesystem::path source;
  std::filesystem::path robot_path;
  RobotDescription robot;
  std::vector<std::uint64_t> seeds{1};
  double model_error = 0.01;         ///< ± fraction of every dynamic parameter (SPEC 5)
  sim::SimulationConfig simulation;  ///< forces, sensors, duration, steps (noise seed per run)
  sim::SinusoidalTrajectory trajectory;
  sim::PidGains gains;
  double controller_omega = 0.0;  ///< when the gains come from `controller.omega`
  bool log_velocity = true;       ///< write dq1..dqn (else estimate differentiates q)
  // Metrics
  double metrics_from = 0.2;  ///< [s] start of every window (after the residual's transient)
  std::vector<std::pair<double, double>> metrics_exclude;
  double singularity_half_width = 0.0;  ///< > 0: a second window excluding ± this around the peak
  std::string
      singularity_link;  ///< link l whose cond(J of O_l) is tracked (default: first force's)
  bool surface_metrics = false;
  bool figures = true;
  std::vector<SchemeSpec> schemes;
};

/// Reads a scenario and loads its robot. Throws extwrench::Error naming file, line and key
/// (unknown keys, wrong types, sizes that do not match the robot, values out of range).
[[nodiscard]] Scenario load_scenario(const std::filesystem::path& path,
                                     const LoadOptions& robot_options = {});

struct SchemeResult {
  std::string name;
  ReplayResult replay;
};

struct SeedResult {
  std::uint64_t seed = 0;
  std::filesystem::path dir;
  long samples = 0;
  double peak_condition = 0.0;  ///< max of cond(J of O_l) over the run (true q)
  double peak_time = 0.0;       ///< [s]
  std::vector<SchemeResult> schemes;
};

struct RunOptions {
  bool figures = true;
  bool progress = false;
};

/// Runs the scenario for every seed: DIR (one seed) or DIR/seed_<s> (several) receives
/// log.csv, model_estimator.urdf, and per scheme <scheme>/config.yaml, estimates.csv,
/// metrics.json and figures. The estimates come from replaying log.csv through the same code
/// as `extwrench estimate`, with the configuration read back from <scheme>/config.yaml.
[[nodiscard]] std::vector<SeedResult> run_scenario(const Scenario& scenario,
                                                   const std::filesystem::path& out_dir,
                                                   const RunOptions& options);

}  // namespace extwrench
