#include "extwrench/observer/momentum_observer.hpp"

#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"

namespace extwrench {
namespace {

Status check_vector(const Eigen::Ref<const VectorX>& v, int n, Channel channel) noexcept {
  if (v.size() != n) return {StatusCode::kWrongSize, channel, static_cast<int>(v.size())};
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return {StatusCode::kNonFinite, channel, i};
  }
  return Status::success();
}

VectorX expand_gains(const VectorX& gains, int n) {
  if (gains.size() != 1 && gains.size() != n) {
    throw Error("MomentumObserver: observer gain: expected 1 or " + std::to_string(n) +
                " values, got " + std::to_string(gains.size()));
  }
  VectorX k = gains.size() == 1 ? VectorX::Constant(n, gains[0]) : gains;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(k[i]) || !(k[i] > 0.0)) {
      throw Error("MomentumObserver: observer gain[" + std::to_string(i) +
                  "]: expected a finite value > 0 [1/s], got " + std::to_string(k[i]));
    }
  }
  return k;
}

bool finite_inertia(const Inertia& in) noexcept {
  return std::isfinite(in.mass) && in.mass >= 0.0 && in.com.allFinite() &&
         in.inertia_com.allFinite();
}

}  // namespace

MomentumObserver::MomentumObserver(Model model, double gain)
    : MomentumObserver(std::move(model), VectorX::Constant(1, gain)) {}

MomentumObserver::MomentumObserver(Model model, const VectorX& gains)
    : model_(std::move(model)), data_(model_), n_(model_.nq()) {
  if (n_ < 1) throw Error("MomentumObserver: model '" + model_.name + "' has no joint");
  gains_ = expand_gains(gains, n_);
  friction_ = JointFriction::from_model(model_);
  validate_friction(friction_, n_, "MomentumObserver: model '" + model_.name + "'");
  nominal_inertia_.reserve(model_.bodies.size());
  for (const Body& b : model_.bodies) nominal_inertia_.push_back(b.inertia);
  r_ = VectorX::Zero(n_);
  m_prev_ = VectorX::Zero(n_);
  gamma_prev_ = VectorX::Zero(n_);
  tau_prev_ = VectorX::Zero(n_);
  q_prev_ = VectorX::Zero(n_);
  dq_prev_ = VectorX::Zero(n_);
  alpha_ = VectorX::Zero(n_);
  tau_f_ = VectorX::Zero(n_);
  gamma_ = VectorX::Zero(n_);
}

void MomentumObserver::set_gains(const VectorX& gains) {
  const VectorX k = expand_gains(gains, n_);
  gains_ = k;      // same size: no allocation
  alpha_dt_ = -1;  // invalidate the cached exponentials
}

void MomentumObserver::set_friction(const JointFriction& friction) {
  validate_friction(friction, n_, "MomentumObserver");
  friction_ = friction;
  if (initialized_) {
    compute_terms(q_prev_, dq_prev_);
    gamma_prev_ = gamma_;
  }
}

void MomentumObserver::apply_payload(int body, const Inertia* payload) noexcept {
  if (payload_body_ >= 0) {
    model_.bodies[static_cast<std::size_t>(payload_body_)].inertia =
        nominal_inertia_[static_cast<std::size_t>(payload_body_)];
  }
  payload_body_ = -1;
  if (payload != nullptr) {
    const auto b = static_cast<std::size_t>(body);
    model_.bodies[b].inertia = nominal_inertia_[b] + *payload;
    payload_body_ = body;
  }
  // Re-anchor: the momentum of the last sample is recomputed with the new model, so the next
  // Δy contains no jump and r stays continuous (the payload is taken as attached at t_k).
  if (initialized_) {
    compute_terms(q_prev_, dq_prev_);
    m_prev_ = data_.momentum;
    gamma_prev_ = gamma_;
  }
}

Status MomentumObserver::set_payload(int body, const Inertia& payload) noexcept {
  if (body < 0 || body >= model_.num_bodies())
    return {StatusCode::kWrongSize, Channel::kNone, body};
  if (!finite_inertia(payload)) return {StatusCode::kNonFinite, Channel::kNone, body};
  apply_payload(body, &payload);
  return Status::success();
}

void MomentumObserver::clear_payload() noexcept { apply_payload(-1, nullptr); }

void MomentumObserver::compute_terms(const Eigen::Ref<const VectorX>& q,
                                     const Eigen::Ref<const VectorX>& dq, Extras extras) noexcept {
  // m = B q̇, Cᵀq̇ and g in one O(n) pass (SPEC §2).
  switch (extras) {
    case Extras::kNone:
      momentum_terms(model_, data_, q, dq);
      break;
    case Extras::kWorldInertias:
      momentum_terms(model_, data_, q, dq);
      world_mass_properties(model_, data_);
      break;
    case Extras::kWorldInertiasAndBias:
      momentum_and_bias_terms(model_, data_, q, dq);
      break;
  }
  extwrench::friction_torque(friction_, dq, tau_f_);
  // γ = Cᵀq̇ − g − τ_f: the state-dependent part of the integrand of (4).
  gamma_ = data_.coriolis_transpose_dq - data_.gravity_torque - tau_f_;
}

Status MomentumObserver::reset(double t, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq) noexcept {
  if (!std::isfinite(t)) return {StatusCode::kNonFinite, Channel::kTime, 0};
  if (Status s = check_vector(q, n_, Channel::kPosition); !s.ok()) return s;
  if (Status s = check_vector(dq, n_, Channel::kVelocity); !s.ok()) return s;
  compute_terms(q, dq);
  t_ = t;
  r_.setZero();
  m_prev_ = data_.momentum;
  gamma_prev_ = gamma_;
  q_prev_ = q;
  dq_prev_ = dq;
  have_tau_ = false;
  initialized_ = true;
  return Status::success();
}

Status MomentumObserver::reset(double t, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq,
                               const Eigen::Ref<const VectorX>& tau) noexcept {
  if (Status s = check_vector(tau, n_, Channel::kTorque); !s.ok()) return s;
  const Status s = reset(t, q, dq);
  if (!s.ok()) return s;
  tau_prev_ = tau;
  have_tau_ = true;
  return s;
}

Status MomentumObserver::validate(double t, const Eigen::Ref<const VectorX>& q,
                                  const Eigen::Ref<const VectorX>& dq,
                                  const Eigen::Ref<const VectorX>& tau) const noexcept {
  if (!initialized_) return {StatusCode::kNotInitialized, Channel::kNone, -1};
  if (!std::isfinite(t)) return {StatusCode::kNonFinite, Channel::kTime, 0};
  if (!(t > t_)) return {StatusCode::kNonIncreasingTime, Channel::kTime, 0};
  if (Status s = check_vector(q, n_, Channel::kPosition); !s.ok()) return s;
  if (Status s = check_vector(dq, n_, Channel::kVelocity); !s.ok()) return s;
  return check_vector(tau, n_, Channel::kTorque);
}

Status MomentumObserver::update(double t, const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau) noexcept {
  // Every input is checked before any state changes: a bad sample leaves no trace.
  if (Status s = validate(t, q, dq, tau); !s.ok()) return s;
  advance(t, q, dq, tau);
  return Status::success();
}

void MomentumObserver::advance(double t, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq,
                               const Eigen::Ref<const VectorX>& tau, Extras extras) noexcept {
  const double dt = t - t_;
  compute_terms(q, dq, extras);
  if (dt != alpha_dt_) {
    alpha_ = (-gains_ * dt).array().exp();  // e^{−K Δt}, recomputed only when Δt changes
    alpha_dt_ = dt;
  }
  if (!have_tau_) tau_prev_ = tau;      // reset without τ: the first interval uses this sample's
  const VectorX& tau_hold = tau_prev_;  // zero-order hold of τ over [t_k, t_{k+1})
  const VectorX& m = data_.momentum;
  const double inv_dt = 1.0 / dt;
  for (int i = 0; i < n_; ++i) {
    // Δy = m_{k+1} − m_k − Δt (τ_k + ½ (γ_k + γ_{k+1}))
    const double dy = m[i] - m_prev_[i] - dt * (tau_hold[i] + 0.5 * (gamma_prev_[i] + gamma_[i]));
    // Exact solution of ṙ = K (Δy/Δt − r) over the step.
    r_[i] = alpha_[i] * r_[i] + (1.0 - alpha_[i]) * dy * inv_dt;
  }
  m_prev_ = m;
  gamma_prev_ = gamma_;
  tau_prev_ = tau;
  have_tau_ = true;
  q_prev_ = q;
  dq_prev_ = dq;
  t_ = t;
}

}  // namespace extwrench
