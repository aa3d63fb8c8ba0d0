// `engine: mujoco` scenarios (docs/simulation.md, docs/mujoco.md): the closed loop of a scenario
// run in MuJoCo — the robot's MJCF with a base force/torque sensor and the scenario's obstacles
// (fixed, or moving mocap bodies) — streamed as log rows like sim::Simulator, with the truth
// from MujocoBridge (mj_contactForce). Part of extwrench::mujoco; the app library reaches it
// through set_mujoco_engine (io/scenario_config.hpp), so it never links MuJoCo.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "extwrench/bridges/mujoco.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/io/scenario_config.hpp"
#include "extwrench/sim/sample_source.hpp"
#include "extwrench/sim/simulator.hpp"

namespace extwrench::mujoco {

/// Names the engine gives what it adds to the robot's MJCF.
inline constexpr const char* kSceneSensorSite = "extwrench_base_sensor";
inline constexpr const char* kSceneForceSensor = "extwrench_base_force";
inline constexpr const char* kSceneTorqueSensor = "extwrench_base_torque";
inline constexpr const char* kSceneObstaclePrefix = "extwrench_obstacle_";

/// The MJCF text MuJoCo simulates for `scenario`: the robot file with a site and <force>/
/// <torque> sensors at the base sensor's pose `X_WS` on the root body, and the obstacles
/// (geoms `extwrench_obstacle_NAME`, in mocap bodies of that name when they move), and a contact
/// <exclude> for every pair of `robot_bodies` (no self-collisions), and the scenario's
/// `mujoco_option` in an <option> of its own, last (MuJoCo merges <option>s attribute by
/// attribute, the last one winning, so the file's other values stay). `X_mj_root` is the root
/// body's pose in MuJoCo's world (the obstacles are given in W, the root's frame).
/// Throws extwrench::Error naming the robot file when it is not MJCF or its root body is not
/// found in its text.
[[nodiscard]] std::string scene_mjcf(const Scenario& scenario, const Pose& X_WS,
                                     const Pose& X_mj_root,
                                     const std::vector<std::string>& robot_bodies = {});

class MujocoSimulator final : public sim::SampleSource {
 public:
  /// Compiles the scene (the robot file's directory resolves its meshes and includes), sets
  /// MuJoCo's step to sample_time / substeps and the initial state to config.q0 or the desired
  /// trajectory's q_d(0). Throws extwrench::Error naming the scenario when MuJoCo rejects it.
  MujocoSimulator(const Scenario& scenario, sim::ComputedTorqueController controller,
                  sim::SimulationConfig config);
  ~MujocoSimulator() override;
  MujocoSimulator(const MujocoSimulator&) = delete;
  MujocoSimulator& operator=(const MujocoSimulator&) = delete;

  [[nodiscard]] long num_samples() const override { return num_samples_; }
  /// The sample at t_k: the controller's torque from the measured q, q̇ applied as
  /// qfrc_applied (and the scenario's forces as xfrc_applied), mj_forward, the bridge's sample
  /// and truth, the sensor models of the scenario; then `substeps` MuJoCo steps to t_{k+1}.
  bool next(Sample& out) override;

  /// MuJoCo's model and data (after next(): the state at t_{k+1}).
  [[nodiscard]] const mjModel_* mj_model() const { return m_; }
  [[nodiscard]] const mjData_* mj_data() const { return d_; }
  /// The contacts of the last sample, per body (MujocoBridge::contacts()).
  [[nodiscard]] std::span<const BodyContactTruth> contacts() const { return bridge_->contacts(); }
  /// The scene MuJoCo simulates (scene_mjcf).
  [[nodiscard]] const std::string& scene() const { return scene_; }

 private:
  void place_obstacles(double t) noexcept;
  void apply_forces(double t, const VectorX& q);

  Model model_;
  sim::ComputedTorqueController controller_;
  sim::SimulationConfig config_;
  std::vector<Obstacle> obstacles_;
  std::string scene_;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  std::unique_ptr<MujocoBridge> bridge_;
  Pose X_mj_root_;
  std::vector<int> qpos_adr_, dof_adr_;
  std::vector<int> mocap_of_obstacle_;  ///< -1 for a fixed obstacle
  std::vector<int> mj_body_of_body_;    ///< a MuJoCo body rigidly attached to each of ours
  sim::JointSensor joint_sensor_;
  Rng noise_;
  Data data_;
  std::vector<ExternalWrench> wrenches_;
  VectorX q_, dq_, qm_, dqm_;
  long k_ = 0;
  long num_samples_ = 0;
};

/// Makes `engine: mujoco` scenarios run in this program (set_mujoco_engine).
void register_mujoco_engine() noexcept;

}  // namespace extwrench::mujoco
