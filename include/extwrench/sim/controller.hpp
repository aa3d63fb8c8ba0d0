// The paper's controller (Sec. IV): feedback linearization with the (perturbed) model plus a PID
// stabilizing part, tracking a sinusoidal joint trajectory.
#pragma once

#include "extwrench/dynamics/data.hpp"
#include "extwrench/sim/trajectory.hpp"

namespace extwrench::sim {

struct PidGains {
  VectorX kp;  ///< (n) [1/s^2]
  VectorX kd;  ///< (n) [1/s]
  VectorX ki;  ///< (n) [1/s^3]
};

/// Gains placing the three poles of each joint's error dynamics
/// (e''' + kd e'' + kp e' + ki e = 0) at -omega: kd = 3ω, kp = 3ω², ki = ω³.
[[nodiscard]] PidGains pid_gains_triple_pole(int n, double omega);

/// τ = B̂(q) (q̈_d + K_d ė + K_p e + K_i ∫e) + ĉ(q, q̇), e = q_d − q, with B̂, ĉ from the
/// controller's own model (one RNEA pass). The integral uses the time between calls.
class ComputedTorqueController {
 public:
  /// Keeps a copy of `model` (the controller's belief). Throws extwrench::Error when the gains
  /// or the trajectory do not have the model's n entries.
  ComputedTorqueController(Model model, SinusoidalTrajectory trajectory, PidGains gains);

  /// Restarts the integral; the next call integrates from time t.
  void reset(double t);
  /// Torque command for the measured state at time t. Returns data().tau's copy.
  const VectorX& update(double t, const Eigen::Ref<const VectorX>& q,
                        const Eigen::Ref<const VectorX>& dq);

  [[nodiscard]] const Model& model() const { return model_; }
  [[nodiscard]] const SinusoidalTrajectory& trajectory() const { return trajectory_; }

 private:
  Model model_;
  Data data_;
  SinusoidalTrajectory trajectory_;
  PidGains gains_;
  VectorX integral_, qd_, dqd_, ddqd_, v_, tau_;
  double last_t_ = 0.0;
};

}  // namespace extwrench::sim
