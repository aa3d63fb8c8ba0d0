// Simulation scenarios (YAML, docs/simulation.md): the file format. Running them is
// app/scenario_run.hpp (`extwrench simulate`).
//
// A scenario names the robot, the desired trajectory and the controller, the forces, the sensor
// models, the seeds and the dynamic-parameter error, and one or more estimator configurations
// ("schemes", in the format of docs/config.md, without `robot`: they use the perturbed model).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "extwrench/io/robot_loader.hpp"
#include "extwrench/sim/sample_source.hpp"
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

/// An obstacle of a MuJoCo scene (`obstacles:` with `engine: mujoco`, docs/simulation.md): a
/// box, sphere or capsule in the world, fixed or moving (a MuJoCo mocap body), with the contact
/// parameters MuJoCo uses for its contacts with the robot (the obstacle's geom has priority).
struct Obstacle {
  enum class Shape { kBox, kSphere, kCapsule };
  enum class Motion { kFixed, kSinusoidal, kLinear };
  std::string name;
  Shape shape = Shape::kBox;
  /// Pose at t = 0 in W (the robot's root frame); a capsule's axis is its z.
  Pose pose = Pose::identity();
  /// box: side lengths; sphere: (radius, 0, 0); capsule: (radius, length of the cylinder, 0) [m].
  Vector3 size = Vector3::Zero();
  Motion motion = Motion::kFixed;
  /// kSinusoidal: p(t) = p0 + amplitude sin(2π frequency t + phase) [m, Hz, rad].
  Vector3 amplitude = Vector3::Zero();
  double frequency = 0.0;
  double phase = 0.0;
  /// kLinear: p(t) = p0 + velocity · clamp(t − start, 0, end − start) [m/s, s].
  Vector3 velocity = Vector3::Zero();
  double start = 0.0;
  double end = 0.0;
  // MuJoCo's contact parameters of the geom (defaults: MuJoCo's own).
  Vector3 friction{1.0, 0.005, 0.0001};  ///< sliding, torsional, rolling
  Eigen::Vector2d solref{0.02, 1.0};     ///< time constant [s], damping ratio
  VectorX solimp = (VectorX(5) << 0.9, 0.95, 0.001, 0.5, 2.0).finished();
  int condim = 3;
  int line = 0;  ///< where it is defined in the scenario

  /// The obstacle's origin in W at time t.
  [[nodiscard]] Vector3 position(double t) const;
};

/// `mujoco_option` (engine: mujoco): attributes of MuJoCo's <option> that the scene sets over
/// the robot file's own (unset: the file's, or MuJoCo's defaults: a pyramidal cone, impratio 1).
struct MujocoOption {
  enum class Cone { kPyramidal, kElliptic };
  /// The friction cone of every contact: MuJoCo's pyramid approximates the Coulomb cone with
  /// four facets; the elliptic cone is the Coulomb cone itself.
  std::optional<Cone> cone;
  std::optional<double> impratio;  ///< friction-to-normal impedance ratio, > 0
};

struct Scenario;

/// What runs `engine: mujoco` (extwrench::mujoco's register_mujoco_engine() installs it): the
/// closed loop of `scenario` in MuJoCo with this controller and the sensor models of `config`.
using MujocoEngine = std::unique_ptr<sim::SampleSource> (*)(
    const Scenario& scenario, sim::ComputedTorqueController controller,
    const sim::SimulationConfig& config);

/// Installs the MuJoCo engine (nullptr removes it). Without one, a scenario with
/// `engine: mujoco` is an error naming the file and line.
void set_mujoco_engine(MujocoEngine engine) noexcept;
[[nodiscard]] MujocoEngine mujoco_engine() noexcept;

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
  /// `engine`: rigid (sim::Simulator, RK4) or mujoco (MuJoCo with `obstacles`, the robot an
  /// MJCF file; run by the registered MujocoEngine).
  enum class Engine { kRigid, kMujoco };
  Engine engine = Engine::kRigid;
  std::vector<Obstacle> obstacles;
  MujocoOption mujoco_option;
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
