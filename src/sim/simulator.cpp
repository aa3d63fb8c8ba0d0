#include "extwrench/sim/simulator.hpp"

#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"

namespace extwrench::sim {
namespace {
// Offset of the joint torques' noise seed from the base sensor's (docs/simulation.md).
constexpr std::uint64_t kTorqueNoiseStream = 0x746f7271;  // "torq"
}  // namespace

Rk4Workspace::Rk4Workspace(const Model& model) : data(model), jacobian(6, model.nq()) {
  const int n = model.nq();
  for (VectorX* v :
       {&tau_ext, &k1q, &k1v, &k2q, &k2v, &k3q, &k3v, &k4q, &k4v, &qs, &vs, &tau_total}) {
    v->setZero(n);
  }
  wrenches.reserve(16);
}

bool true_acceleration(const Model& model, std::span<const ForceProfile> forces, double t,
                       const VectorX& q, const VectorX& dq, const VectorX& tau, Rk4Workspace& ws) {
  forward_kinematics(model, ws.data, q);
  evaluate_forces(forces, t, ws.data, ws.wrenches);
  external_joint_torques(model, ws.data, ws.wrenches, ws.jacobian, ws.tau_ext);
  // (1) B q̈ + C q̇ + g = τ + τ_ext
  ws.tau_total = tau + ws.tau_ext;
  return forward_dynamics(model, ws.data, q, dq, ws.tau_total);
}

bool rk4_step(const Model& model, std::span<const ForceProfile> forces, double t, double h,
              const VectorX& tau, VectorX& q, VectorX& dq, Rk4Workspace& ws) {
  // State x = (q, q̇), ẋ = (q̇, q̈(t, q, q̇)).
  if (!true_acceleration(model, forces, t, q, dq, tau, ws)) return false;
  ws.k1q = dq;
  ws.k1v = ws.data.ddq;
  ws.qs = q + 0.5 * h * ws.k1q;
  ws.vs = dq + 0.5 * h * ws.k1v;
  if (!true_acceleration(model, forces, t + 0.5 * h, ws.qs, ws.vs, tau, ws)) return false;
  ws.k2q = ws.vs;
  ws.k2v = ws.data.ddq;
  ws.qs = q + 0.5 * h * ws.k2q;
  ws.vs = dq + 0.5 * h * ws.k2v;
  if (!true_acceleration(model, forces, t + 0.5 * h, ws.qs, ws.vs, tau, ws)) return false;
  ws.k3q = ws.vs;
  ws.k3v = ws.data.ddq;
  ws.qs = q + h * ws.k3q;
  ws.vs = dq + h * ws.k3v;
  if (!true_acceleration(model, forces, t + h, ws.qs, ws.vs, tau, ws)) return false;
  ws.k4q = ws.vs;
  ws.k4v = ws.data.ddq;
  q += (h / 6.0) * (ws.k1q + 2.0 * ws.k2q + 2.0 * ws.k3q + ws.k4q);
  dq += (h / 6.0) * (ws.k1v + 2.0 * ws.k2v + 2.0 * ws.k3v + ws.k4v);
  return true;
}

Simulator::Simulator(const Model& model, ComputedTorqueController controller,
                     SimulationConfig config)
    : model_(model),
      controller_(std::move(controller)),
      config_(std::move(config)),
      ws_(model_),
      joint_sensor_(config_.encoder, model_.nq()),
      noise_(config_.noise_seed),
      torque_noise_(config_.noise_seed + kTorqueNoiseStream) {
  const int n = model_.nq();
  config_.joint_torque.validate(n, "simulator: joint_torque");
  if (controller_.model().nq() != n) {
    throw Error("simulator: the controller's model has " +
                std::to_string(controller_.model().nq()) + " joints, the robot " +
                std::to_string(n));
  }
  if (!(config_.sample_time > 0.0) || !std::isfinite(config_.sample_time)) {
    throw Error("simulator: sample_time must be positive");
  }
  if (config_.substeps < 1) throw Error("simulator: substeps must be >= 1");
  if (!(config_.duration >= 0.0) || !std::isfinite(config_.duration)) {
    throw Error("simulator: duration must be finite and >= 0");
  }
  for (ForceProfile& f : config_.forces) f.resolve(model_);
  q_.setZero(n);
  dq_.setZero(n);
  VectorX ddq(n);
  controller_.trajectory().evaluate(0.0, q_, dq_, ddq);
  if (config_.q0.size() != 0) {
    if (config_.q0.size() != n)
      throw Error("simulator: q0 needs " + std::to_string(n) + " entries");
    q_ = config_.q0;
  }
  if (config_.dq0.size() != 0) {
    if (config_.dq0.size() != n)
      throw Error("simulator: dq0 needs " + std::to_string(n) + " entries");
    dq_ = config_.dq0;
  }
  qm_.setZero(n);
  dqm_.setZero(n);
  tau_friction_.setZero(n);
  presliding_state_.setZero(n);  // at rest the presliding state is unknown, as the observer's
  presliding_q_ = q_;
  // Samples at k·Ts for k·Ts <= duration (a tiny tolerance absorbs the division's rounding).
  num_samples_ = static_cast<long>(std::floor(config_.duration / config_.sample_time + 1e-9)) + 1;
  controller_.reset(0.0);
}

// τ += τ_f of the true motion + σ n (config_.joint_torque), the Dahl state advanced by the true
// Δq since the last sample as the observer advances its own.
void Simulator::add_joint_torque_terms(VectorX& tau) noexcept {
  const JointTorqueModel& jt = config_.joint_torque;
  if (jt.friction) {
    const JointFriction& f = *jt.friction;
    if (f.sign == SmoothSign::kDahl) {
      for (Eigen::Index i = 0; i < q_.size(); ++i)
        presliding_state_[i] =
            dahl_step(presliding_state_[i], q_[i] - presliding_q_[i], f.presliding[i]);
      presliding_q_ = q_;
    }
    friction_torque(f, dq_, presliding_state_, tau_friction_);
    tau += tau_friction_;
  }
  // One draw per joint and sample whatever σ_i (a joint with σ_i = 0 included), so that the
  // other joints' noise does not depend on which are quiet.
  if (jt.noise.size() == tau.size())
    for (Eigen::Index i = 0; i < tau.size(); ++i) tau[i] += jt.noise[i] * torque_noise_.normal();
}

bool Simulator::next(Sample& out) {
  if (k_ >= num_samples_) return false;
  const int n = model_.nq();
  const double t = sample_instant(k_, config_.sample_time);
  joint_sensor_.measure(t, q_, dq_, qm_, dqm_);
  const VectorX& tau = controller_.update(t, qm_, dqm_);

  out.t = t;
  out.q = qm_;
  out.dq = dqm_;
  out.tau = tau;
  if (config_.joint_torque.active()) add_joint_torque_terms(out.tau);
  // The truth at t_k: true acceleration under τ_k, then one RNEA pass with the external
  // wrenches down to link 0 for the base reading (eqs. 9–10).
  if (!true_acceleration(model_, config_.forces, t, q_, dq_, tau, ws_)) {
    throw Error("simulator: the mass matrix is not positive definite at t = " + std::to_string(t));
  }
  const VectorX ddq = ws_.data.ddq;
  rnea(model_, ws_.data, q_, dq_, ddq, ws_.wrenches);
  const Vector6 ideal = sensor_reading(ws_.data, config_.sensor.X_WS);
  config_.sensor.write_reading(ideal, noise_, out);

  out.has_truth = true;
  out.has_true_tau_ext = true;
  Truth& truth = out.truth;
  truth.link.clear();
  truth.body = -1;
  truth.contacts = static_cast<int>(ws_.wrenches.size());
  truth.force_W.setZero();
  truth.moment_W.setZero();
  truth.point_W.setZero();
  for (const ExternalWrench& w : ws_.wrenches) {
    const std::string& name = model_.bodies[static_cast<std::size_t>(w.body)].name;
    if (truth.body < 0) {
      truth.body = w.body;
      truth.point_W = w.point_W;
      truth.link = name;
    } else if (w.body != truth.body) {
      truth.link += "+" + name;
    }
    truth.force_W += w.force_W;
    truth.moment_W += w.moment_W;
  }
  truth.tau_ext = ws_.tau_ext;

  // Advance to t_{k+1} with τ_k held (zero-order hold, as a digital controller does).
  const double h = config_.sample_time / config_.substeps;
  for (int s = 0; s < config_.substeps; ++s) {
    if (!rk4_step(model_, config_.forces, t + s * h, h, tau, q_, dq_, ws_)) {
      throw Error("simulator: the mass matrix is not positive definite near t = " +
                  std::to_string(t));
    }
  }
  if (!q_.allFinite() || !dq_.allFinite()) {
    throw Error("simulator: the state diverged near t = " + std::to_string(t) +
                " (reduce the step or the gains)");
  }
  (void)n;
  ++k_;
  return true;
}

}  // namespace extwrench::sim
