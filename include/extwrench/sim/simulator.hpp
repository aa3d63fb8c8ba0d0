// Closed-loop simulation of the true robot: RK4 at a fixed step, torque held between samples.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/sim/controller.hpp"
#include "extwrench/sim/force_profile.hpp"
#include "extwrench/sim/sample_source.hpp"
#include "extwrench/sim/sensor_model.hpp"

namespace extwrench::sim {

struct SimulationConfig {
  double duration = 6.0;      ///< [s]; samples at t = sample_instant(k, sample_time) <= duration
  double sample_time = 1e-3;  ///< controller and logging period [s]
  int substeps = 1;           ///< RK4 steps per sample (integration step = sample_time / substeps)
  std::vector<ForceProfile> forces;
  BaseSensorModel sensor;
  EncoderModel encoder;
  JointTorqueModel joint_torque;  ///< what the logged τ carries beyond the command (none)
  std::uint64_t noise_seed = 1;   ///< seed of the sensor noise streams
  /// Initial state; empty: the desired trajectory's q_d(0), q̇_d(0).
  VectorX q0, dq0;
};

/// The instant of sample k [s]: k / rate when the rate 1 / sample_time is a whole number of
/// hertz (1 kHz: t = 0.009, the double nearest the decimal, where 9 × 0.001 writes
/// 0.009000000000000001 into the log), else k · sample_time.
inline double sample_instant(long k, double sample_time) noexcept {
  const double rate = 1.0 / sample_time;
  const double whole = std::round(rate);
  return whole >= 1.0 && std::abs(rate - whole) <= 1e-9 * whole
             ? static_cast<double>(k) / whole
             : static_cast<double>(k) * sample_time;
}

/// Workspace of one RK4 step (sized once for a model).
struct Rk4Workspace {
  explicit Rk4Workspace(const Model& model);
  Data data;
  Matrix6X jacobian;
  std::vector<ExternalWrench> wrenches;
  VectorX tau_ext, k1q, k1v, k2q, k2v, k3q, k3v, k4q, k4v, qs, vs, tau_total;
};

/// True acceleration q̈ = B⁻¹ (τ + τ_ext − c) at (t, q, q̇) with the forces active at t.
/// Writes workspace.data.ddq and workspace.tau_ext. Returns false if B is not positive definite.
bool true_acceleration(const Model& model, std::span<const ForceProfile> forces, double t,
                       const VectorX& q, const VectorX& dq, const VectorX& tau, Rk4Workspace& ws);

/// One classical Runge–Kutta step of length h from t with τ held constant; forces are
/// re-evaluated at the stage times and configurations. Returns false on a singular B.
bool rk4_step(const Model& model, std::span<const ForceProfile> forces, double t, double h,
              const VectorX& tau, VectorX& q, VectorX& dq, Rk4Workspace& ws);

/// The simulated robot in closed loop with its controller. Each call to next() returns one
/// sample (streaming: memory does not grow with the duration).
class Simulator final : public SampleSource {
 public:
  /// `model` is the true robot (nominal parameters). Forces are resolved against it. Throws
  /// extwrench::Error on sizes that do not match the model, or a non-positive step.
  Simulator(const Model& model, ComputedTorqueController controller, SimulationConfig config);

  /// Number of samples the run produces.
  [[nodiscard]] long num_samples() const override { return num_samples_; }
  /// Fills `out` with the next sample (measurements at t_k, the torque commanded at t_k and the
  /// truth at t_k), then integrates to t_{k+1}. Returns false when the run is over. Throws
  /// extwrench::Error if the simulation diverges (non-finite state, singular B).
  bool next(Sample& out) override;

  [[nodiscard]] const Model& model() const { return model_; }
  [[nodiscard]] const SimulationConfig& config() const { return config_; }
  /// True state (after the last next()).
  [[nodiscard]] const VectorX& q() const { return q_; }
  [[nodiscard]] const VectorX& dq() const { return dq_; }

 private:
  void add_joint_torque_terms(VectorX& tau) noexcept;

  Model model_;
  ComputedTorqueController controller_;
  SimulationConfig config_;
  Rk4Workspace ws_;
  JointSensor joint_sensor_;
  Rng noise_;
  Rng torque_noise_;  ///< the joint torques' own stream: the base sensor's stays as without it
  VectorX q_, dq_, qm_, dqm_;
  /// config_.joint_torque's friction: τ_f, and the Dahl sign's state with the q it was advanced to
  VectorX tau_friction_, presliding_state_, presliding_q_;
  long k_ = 0;
  long num_samples_ = 0;
};

}  // namespace extwrench::sim
