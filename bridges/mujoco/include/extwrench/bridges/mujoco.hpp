// The live bridge from a MuJoCo simulation to the estimator (docs/mujoco.md "The bridge"): each
// step, mjData -> the estimator's Sample (q, q̇, the applied joint torque, the base F/T reading)
// and the truth MuJoCo computed (contact forces per link). Set-up allocates; step() does not.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "extwrench/core/random.hpp"
#include "extwrench/core/sample.hpp"
#include "extwrench/model/model.hpp"

struct mjModel_;
struct mjData_;

namespace extwrench::mujoco {

struct BridgeOptions {
  /// MuJoCo <force> and <torque> sensors of the base F/T sensor (on a site of link 0; the
  /// site is S). Empty names: the reading is left out (has_force, has_moment false).
  std::string force_sensor = "base_force";
  std::string torque_sensor = "base_torque";
  /// Encoder resolution [rad | m]: q is rounded to a multiple of it; 0 keeps MuJoCo's qpos.
  double encoder_resolution = 0.0;
  /// Standard deviations of white noise added to q [rad | m], q̇, τ and the reading (S);
  /// 0 = none. Seeded: the same seed gives the same noise.
  double position_noise = 0.0;
  double velocity_noise = 0.0;
  double torque_noise = 0.0;
  double force_noise_S = 0.0;
  double moment_noise_S = 0.0;
  std::uint64_t seed = 1;
};

/// What MuJoCo applied to one body of the model this step, world frame: contacts of the robot
/// with anything but itself (mj_contactForce) and xfrc_applied.
struct BodyContactTruth {
  int body = -1;
  int points = 0;                      ///< contact points (an xfrc_applied counts as one)
  Vector3 force_W = Vector3::Zero();   ///< resultant force on the body [N]
  Vector3 point_W = Vector3::Zero();   ///< centre of pressure on the line of action [m]
  Vector3 moment_W = Vector3::Zero();  ///< the pure moment left about point_W, along force_W [N m]
};

class MujocoBridge {
 public:
  /// Maps `model`'s joints to `m`'s by name and its bodies to MuJoCo bodies (each MuJoCo body
  /// whose name is a frame of `model` belongs to that frame's body). Throws extwrench::Error
  /// for a joint of `model` missing in `m`, a sensor name not found or not a force/torque
  /// sensor. `m` must outlive the bridge.
  MujocoBridge(const mjModel_* m, const Model& model, BridgeOptions options = {});

  /// Reads `d` after mj_forward and before the integrator (mj_Euler, mj_implicit, ...): then
  /// qpos, qvel, the sensors and the contacts describe the same instant (after mj_step, qpos
  /// and qvel are one step ahead of the rest). sample() and contacts() describe that state.
  /// Allocation-free, noexcept. The torque is what acted on the joints: actuator forces plus
  /// qfrc_applied (MuJoCo's passive damping and friction loss are left to the estimator's
  /// friction model, as on a real robot).
  void step(const mjData_* d) noexcept;

  [[nodiscard]] const Sample& sample() const { return sample_; }
  /// Bodies in contact this step (one entry per body of the model; the first ones used).
  [[nodiscard]] std::span<const BodyContactTruth> contacts() const {
    return {contacts_.data(), static_cast<std::size_t>(num_contacts_)};
  }

 private:
  void read_measurements(const mjData_* d) noexcept;
  void read_truth(const mjData_* d) noexcept;
  void add_wrench(int mj_body, const Vector3& force_mj, const Vector3& point_mj,
                  const Vector3& torque_mj, const mjData_* d) noexcept;
  void finish_truth() noexcept;

  const mjModel_* m_;
  BridgeOptions options_;
  std::vector<int> qpos_adr_, dof_adr_;   ///< per our joint i - 1
  std::vector<int> body_of_mj_body_;      ///< MuJoCo body -> our body, -1 when not the robot's
  std::vector<std::string> body_names_;   ///< our bodies' names
  int force_adr_ = -1, torque_adr_ = -1;  ///< sensordata addresses
  Pose X_root_W_mj_;                      ///< MuJoCo world -> our world (the root's frame)
  int root_mj_ = -1;
  Rng rng_;
  Sample sample_;
  // Per-body accumulation: Σ f, Σ (p × f) + τ about MuJoCo's origin, Σ |f| p, Σ |f|.
  struct Accumulator {
    int points = 0;
    Vector3 force = Vector3::Zero(), moment_O = Vector3::Zero(), weighted_point = Vector3::Zero();
    double weight = 0.0;
  };
  std::vector<Accumulator> accumulators_;
  std::vector<BodyContactTruth> contacts_;
  int num_contacts_ = 0;
  std::vector<double> jacp_;  ///< 3 × nv, for τ_ext
};

}  // namespace extwrench::mujoco
