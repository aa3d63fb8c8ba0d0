#include "extwrench/observer/momentum_observer.hpp"

#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/core/input_checks.hpp"
#include "extwrench/core/time_step.hpp"
#include "extwrench/dynamics/momentum.hpp"

namespace extwrench {

VectorX MomentumObserver::checked_gains(const VectorX& gains, int n) {
  if (gains.size() != 1 && gains.size() != n) {
    throw Error("MomentumObserver: observer gain: expected 1 or " + std::to_string(n) +
                " values, got " + std::to_string(gains.size()));
  }
  VectorX k = per_joint(gains, n);
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(k[i]) || !(k[i] > 0.0)) {
      throw Error("MomentumObserver: observer gain[" + std::to_string(i) +
                  "]: expected a finite value > 0 [1/s], got " + std::to_string(k[i]));
    }
  }
  return k;
}

MomentumObserver::MomentumObserver(const Model& model, double gain)
    : MomentumObserver(model, VectorX::Constant(1, gain)) {}

MomentumObserver::MomentumObserver(const Model& model, const VectorX& gains) : n_(model.nq()) {
  if (n_ < 1) throw Error("MomentumObserver: model '" + model.name + "' has no joint");
  gains_ = checked_gains(gains, n_);
  inertia_correction_ = VectorX::Zero(n_);
  friction_ = JointFriction::from_model(model);
  validate_friction(friction_, n_, "MomentumObserver: model '" + model.name + "'");
  r_ = VectorX::Zero(n_);
  presliding_state_ = VectorX::Zero(n_);
  m_prev_ = VectorX::Zero(n_);
  gamma_prev_ = VectorX::Zero(n_);
  tau_prev_ = VectorX::Zero(n_);
  q_prev_ = VectorX::Zero(n_);
  dq_prev_ = VectorX::Zero(n_);
  friction_dq_prev_ = VectorX::Zero(n_);
  alpha_ = VectorX::Zero(n_);
  tau_f_ = VectorX::Zero(n_);
  gamma_ = VectorX::Zero(n_);
}

void MomentumObserver::set_gains(const VectorX& gains) {
  const VectorX k = checked_gains(gains, n_);
  gains_ = k;      // same size: no allocation
  alpha_dt_ = -1;  // invalidate the cached exponentials
}

void MomentumObserver::set_friction(const JointFriction& friction) {
  validate_friction(friction, n_, "MomentumObserver");
  friction_ = friction;
  if (initialized_) {
    // γ_k = Cᵀq̇ − g − τ_f at sample k: swap the old τ_f(q̇_k) for the new one.
    gamma_ = tau_f_;
    extwrench::friction_torque(friction_, friction_dq_prev_, presliding_state_, tau_f_);
    gamma_prev_ += gamma_ - tau_f_;
  }
}

VectorX MomentumObserver::checked_inertia_correction(const VectorX& inertia_correction, int n) {
  if (inertia_correction.size() != 1 && inertia_correction.size() != n) {
    throw Error("MomentumObserver: observer.inertia_correction: expected 1 or " +
                std::to_string(n) + " values, got " + std::to_string(inertia_correction.size()));
  }
  if (!inertia_correction.allFinite())
    throw Error("MomentumObserver: observer.inertia_correction: expected finite values [kg m^2]");
  return per_joint(inertia_correction, n);
}

void MomentumObserver::set_inertia_correction(const VectorX& inertia_correction) {
  const VectorX delta = checked_inertia_correction(inertia_correction, n_);
  // The last momentum with the new δI: the next Δy contains no jump (as reanchor).
  if (initialized_) m_prev_ += (delta - inertia_correction_).cwiseProduct(dq_prev_);
  inertia_correction_ = delta;
}

void MomentumObserver::shift_offset(const Eigen::Ref<const VectorX>& delta) noexcept {
  friction_.offset += delta;
  if (initialized_) {
    // τ_f(q̇) grows by δ: γ = Cᵀq̇ − g − τ_f of the last sample drops by it (see set_friction).
    tau_f_ += delta;
    gamma_prev_ -= delta;
  }
}

void MomentumObserver::set_offset(const Eigen::Ref<const VectorX>& offset) noexcept {
  friction_.offset = offset;
}

void MomentumObserver::integrand(const Data& data, const Eigen::Ref<const VectorX>& dq) noexcept {
  extwrench::friction_torque(friction_, dq, presliding_state_, tau_f_);
  // γ = Cᵀq̇ − g − τ_f: the state-dependent part of the integrand of (4).
  gamma_ = data.coriolis_transpose_dq - data.gravity_torque - tau_f_;
}

void MomentumObserver::anchor_momentum(const Data& data,
                                       const Eigen::Ref<const VectorX>& dq) noexcept {
  for (int i = 0; i < n_; ++i) m_prev_[i] = data.momentum[i] + inertia_correction_[i] * dq[i];
}

void MomentumObserver::reanchor(const Model& model, Data& data) noexcept {
  // The momentum of the last sample is recomputed with the edited model, so the next Δy
  // contains no jump and r stays continuous.
  if (!initialized_) return;
  momentum_terms(model, data, q_prev_, dq_prev_);
  integrand(data, friction_dq_prev_);
  anchor_momentum(data, dq_prev_);
  gamma_prev_ = gamma_;
}

// A model or workspace of another size than the observer's: the momentum pass wrote past the
// workspace's arrays and returned ok (rnea throws on it; these are noexcept). Sizes only, as
// rnea's check_data: Data::matches also compares the inertias its rnea caches, which a payload
// changes in the estimator's model without concerning the momentum pass.
bool MomentumObserver::sized_for(const Model& model, const Data& data) const noexcept {
  return model.nq() == n_ && static_cast<int>(data.X_WB.size()) == model.num_bodies() &&
         data.momentum.size() == n_;
}

Status MomentumObserver::reset(const Model& model, Data& data, double t,
                               const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq) noexcept {
  if (!sized_for(model, data)) return {StatusCode::kWrongSize, Channel::kNone, -1};
  if (!usable_time(t)) return {StatusCode::kNonFinite, Channel::kTime, 0};
  if (Status s = check_vector(q, n_, Channel::kPosition); !s.ok()) return s;
  if (Status s = check_vector(dq, n_, Channel::kVelocity); !s.ok()) return s;
  // m = B q̇, Cᵀq̇ and g in one O(n) pass (eq. 4).
  momentum_terms(model, data, q, dq);
  presliding_state_.setZero();  // the presliding state at rest is unknown: no friction
  integrand(data, dq);
  t_ = t;
  r_.setZero();
  anchor_momentum(data, dq);
  gamma_prev_ = gamma_;
  q_prev_ = q;
  dq_prev_ = dq;
  friction_dq_prev_ = dq;
  have_tau_ = false;
  initialized_ = true;
  return Status::success();
}

Status MomentumObserver::reset(const Model& model, Data& data, double t,
                               const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq,
                               const Eigen::Ref<const VectorX>& tau) noexcept {
  if (Status s = check_vector(tau, n_, Channel::kTorque); !s.ok()) return s;
  const Status s = reset(model, data, t, q, dq);
  if (!s.ok()) return s;
  tau_prev_ = tau;
  have_tau_ = true;
  return s;
}

Status MomentumObserver::validate(double t, const Eigen::Ref<const VectorX>& q,
                                  const Eigen::Ref<const VectorX>& dq,
                                  const Eigen::Ref<const VectorX>& tau) const noexcept {
  if (!initialized_) return {StatusCode::kNotInitialized, Channel::kNone, -1};
  if (!usable_time(t)) return {StatusCode::kNonFinite, Channel::kTime, 0};
  if (!(t - t_ >= kShortestTimeStep)) return {StatusCode::kNonIncreasingTime, Channel::kTime, 0};
  if (Status s = check_vector(q, n_, Channel::kPosition); !s.ok()) return s;
  if (Status s = check_vector(dq, n_, Channel::kVelocity); !s.ok()) return s;
  return check_vector(tau, n_, Channel::kTorque);
}

Status MomentumObserver::update(const Model& model, Data& data, double t,
                                const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau) noexcept {
  // Every input is checked before any state changes: a bad sample leaves no trace.
  if (!sized_for(model, data)) return {StatusCode::kWrongSize, Channel::kNone, -1};
  if (Status s = validate(t, q, dq, tau); !s.ok()) return s;
  momentum_terms(model, data, q, dq);  // m = B q̇, Cᵀq̇ and g in one O(n) pass (eq. 4)
  integrate(data, t, q, dq, tau);
  return Status::success();
}

void MomentumObserver::integrate(const Data& data, double t, const Eigen::Ref<const VectorX>& q,
                                 const Eigen::Ref<const VectorX>& dq,
                                 const Eigen::Ref<const VectorX>& tau) noexcept {
  integrate(data, t, q, dq, tau, dq);
}

void MomentumObserver::integrate(const Data& data, double t, const Eigen::Ref<const VectorX>& q,
                                 const Eigen::Ref<const VectorX>& dq,
                                 const Eigen::Ref<const VectorX>& tau,
                                 const Eigen::Ref<const VectorX>& friction_dq) noexcept {
  const double dt = t - t_;
  if (friction_.sign == SmoothSign::kDahl) {
    for (int i = 0; i < n_; ++i)
      presliding_state_[i] =
          dahl_step(presliding_state_[i], q[i] - q_prev_[i], friction_.presliding[i]);
  }
  integrand(data, friction_dq);
  if (dt != alpha_dt_) {
    alpha_ = (-gains_ * dt).array().exp();  // e^{−K Δt}, recomputed only when Δt changes
    alpha_dt_ = dt;
  }
  if (!have_tau_) tau_prev_ = tau;      // reset without τ: the first interval uses this sample's
  const VectorX& tau_hold = tau_prev_;  // zero-order hold of τ over [t_k, t_{k+1})
  const VectorX& m = data.momentum;
  const double inv_dt = 1.0 / dt;
  for (int i = 0; i < n_; ++i) {
    const double p = m[i] + inertia_correction_[i] * dq[i];  // p = B q̇ + δI q̇ (δI = 0: m)
    // Δy = p_{k+1} − p_k − Δt (τ_k + ½ (γ_k + γ_{k+1}))
    const double dy = p - m_prev_[i] - dt * (tau_hold[i] + 0.5 * (gamma_prev_[i] + gamma_[i]));
    // Exact solution of ṙ = K (Δy/Δt − r) over the step.
    r_[i] = alpha_[i] * r_[i] + (1.0 - alpha_[i]) * dy * inv_dt;
    m_prev_[i] = p;
  }
  gamma_prev_ = gamma_;
  tau_prev_ = tau;
  have_tau_ = true;
  q_prev_ = q;
  dq_prev_ = dq;
  friction_dq_prev_ = friction_dq;
  t_ = t;
}

}  // namespace extwrench
