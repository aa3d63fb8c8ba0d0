#include "extwrench/sim/controller.hpp"

#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/rnea.hpp"

namespace extwrench::sim {

PidGains pid_gains_triple_pole(int n, double omega) {
  PidGains g;
  g.kd = VectorX::Constant(n, 3.0 * omega);
  g.kp = VectorX::Constant(n, 3.0 * omega * omega);
  g.ki = VectorX::Constant(n, omega * omega * omega);
  return g;
}

ComputedTorqueController::ComputedTorqueController(Model model, SinusoidalTrajectory trajectory,
                                                   PidGains gains)
    : model_(std::move(model)),
      data_(model_),
      trajectory_(std::move(trajectory)),
      gains_(std::move(gains)) {
  const int n = model_.nq();
  if (trajectory_.size() != n) {
    throw Error("controller: the trajectory needs " + std::to_string(n) +
                " entries per field (offset, amplitude, frequency, phase)");
  }
  if (gains_.kp.size() != n || gains_.kd.size() != n || gains_.ki.size() != n) {
    throw Error("controller: kp, kd and ki need " + std::to_string(n) + " entries");
  }
  integral_ = VectorX::Zero(n);
  qd_.resize(n);
  dqd_.resize(n);
  ddqd_.resize(n);
  v_.resize(n);
  tau_.resize(n);
}

void ComputedTorqueController::reset(double t) {
  integral_.setZero();
  last_t_ = t;
}

const VectorX& ComputedTorqueController::update(double t, const Eigen::Ref<const VectorX>& q,
                                                const Eigen::Ref<const VectorX>& dq) {
  trajectory_.evaluate(t, qd_, dqd_, ddqd_);
  const double dt = t - last_t_;
  last_t_ = t;
  // Rectangle rule on e at the current sample (the command is held until the next one).
  integral_ += dt * (qd_ - q);
  // Stabilizing part: v = q̈_d + K_d ė + K_p e + K_i ∫e
  v_ = ddqd_ + gains_.kd.cwiseProduct(dqd_ - dq) + gains_.kp.cwiseProduct(qd_ - q) +
       gains_.ki.cwiseProduct(integral_);
  // Feedback linearization with the believed model: τ = B̂ v + ĉ (one RNEA pass)
  tau_ = rnea(model_, data_, q, dq, v_);
  return tau_;
}

}  // namespace extwrench::sim
