// The momentum residual (eq. 4, docs/method.md#momentum-residual): a virtual sensor of the external
// joint torques.
//
//   r(t) = K [ m(t) − m(0) − ∫₀ᵗ ( τ − τ_f + Cᵀ(q,q̇) q̇ − g(q) + r ) ds ],   m = B(q) q̇   (4)
//
// so that ṙ = K (τ_ext − r): r is a first-order low-pass of τ_ext with time constants 1/K_i.
// τ_f is the known joint friction (friction.hpp). Every model term is O(n) (momentum_terms).
//
// Discretization (exact for the first-order law). Write y(t) = m(t) − ∫ β, β = τ − τ_f + Cᵀq̇ − g,
// so that ṙ = K (ẏ − r). Between two samples t_k < t_{k+1}, ẏ is taken constant,
// ẏ ≈ Δy/Δt, and the linear ODE is integrated exactly:
//
//   r_{k+1} = e^{−K Δt} r_k + (1 − e^{−K Δt}) Δy/Δt,
//   Δy = m_{k+1} − m_k − Δt [ τ_k + ½ (γ_k + γ_{k+1}) ],   γ = Cᵀq̇ − g − τ_f,
//
// with the actual Δt from the time stamps (non-uniform steps are integrated correctly, no
// stability limit on K Δt). The commanded torque is held between samples (zero-order hold, as a
// digital controller applies it: τ_k acts on [t_k, t_{k+1})); the state-dependent terms γ use the
// trapezoidal rule. For a constant τ_ext starting at a sample, r_k = (1 − e^{−K (t_k − t_0)}) τ_ext
// up to the trapezoidal error of γ (O(Δt²)).
//
// The observer is state only, in the (model, data) style of the dynamics functions: the caller
// owns the Model and the Data and passes them to each call (the ContactEstimator passes its own,
// payload included). Every member is a value: the observer copies and moves freely.
#pragma once

#include "extwrench/core/status.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/observer/friction.hpp"

namespace extwrench {

class MomentumObserver {
 public:
  /// Sizes every buffer once for `model`'s n joints. `gains`: K_i > 0 [1/s], size n, or size 1
  /// for the same K on every joint. Friction defaults to the model's Joint::damping /
  /// Joint::friction. Throws extwrench::Error on a bad gain or an empty model.
  MomentumObserver(const Model& model, const VectorX& gains);
  MomentumObserver(const Model& model, double gain);

  /// K expanded to n entries; throws extwrench::Error unless size 1 or n, entries finite > 0.
  [[nodiscard]] static VectorX checked_gains(const VectorX& gains, int n);

  /// Sets K (size n or 1, every entry > 0 and finite). Throws extwrench::Error otherwise.
  /// Allocation-free; the residual keeps its value.
  void set_gains(const VectorX& gains);
  /// Throws extwrench::Error on bad sizes. Once initialized, the integrand of the current
  /// interval is corrected to the new friction at the last q̇.
  void set_friction(const JointFriction& friction);
  /// Adds `delta` (n) to the friction's torque offsets o_i (drift tracking): allocation-free,
  /// the current interval's integrand corrected like set_friction. Needs friction().offset of
  /// size n (set_friction with an offset first).
  void shift_offset(const Eigen::Ref<const VectorX>& delta) noexcept;
  /// δI expanded to n entries; throws extwrench::Error unless size 1 or n and finite.
  [[nodiscard]] static VectorX checked_inertia_correction(const VectorX& inertia_correction, int n);
  /// Sets δI (size n or 1, finite, any sign): the momentum becomes p = B(q) q̇ + δI q̇, a
  /// constant error of the inertia along each joint (calibration.hpp). Throws extwrench::Error
  /// on a bad size or value. Once initialized, the last momentum is corrected too (no jump).
  void set_inertia_correction(const VectorX& inertia_correction);
  [[nodiscard]] const VectorX& inertia_correction() const noexcept { return inertia_correction_; }

  /// Sets the friction's torque offsets o_i to `offset` (n) exactly, for a reset to follow
  /// (the current interval's integrand is not corrected). Allocation-free; needs friction().offset
  /// of size n.
  void set_offset(const Eigen::Ref<const VectorX>& offset) noexcept;

  /// Starts (or restarts) the observer at time t: r = 0, m(0) = B(q) q̇ (momentum_terms on
  /// `data`). The torque of the interval [t, t_1) is `tau`; the overload without it takes the
  /// first update's torque. kWrongSize (channel none) for a model of another size than the
  /// observer's or a `data` of another size than the model, and nothing is changed.
  [[nodiscard]] Status reset(const Model& model, Data& data, double t,
                             const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq) noexcept;
  [[nodiscard]] Status reset(const Model& model, Data& data, double t,
                             const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq,
                             const Eigen::Ref<const VectorX>& tau) noexcept;

  /// One sample: t > previous t, q, q̇, τ (commanded joint torques) of size n, all finite.
  /// validate(), then momentum_terms(model, data, q, q̇), then integrate(). On an input error the
  /// Status names the channel and index and nothing is changed (the state stays bit-identical);
  /// kWrongSize (channel none) for a model or `data` of another size. O(n), no allocation.
  [[nodiscard]] Status update(const Model& model, Data& data, double t,
                              const Eigen::Ref<const VectorX>& q,
                              const Eigen::Ref<const VectorX>& dq,
                              const Eigen::Ref<const VectorX>& tau) noexcept;

  /// Checks (t, q, q̇, τ) as update() would, without changing anything.
  [[nodiscard]] Status validate(double t, const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau) const noexcept;

  /// The integration step of update() for a caller that validated (t, q, q̇, τ) and already ran
  /// momentum_terms or momentum_and_bias_terms at (q, q̇): reads data.momentum,
  /// data.coriolis_transpose_dq and data.gravity_torque; writes residual(), friction_torque().
  void integrate(const Data& data, double t, const Eigen::Ref<const VectorX>& q,
                 const Eigen::Ref<const VectorX>& dq,
                 const Eigen::Ref<const VectorX>& tau) noexcept;
  /// As integrate, with the joint friction τ_f evaluated at `friction_dq` rather than at the q̇
  /// of the momentum (the estimator's velocity filter: the momentum takes the filtered q̇, the
  /// friction the measured one, whose sign a filter would delay at every reversal).
  void integrate(const Data& data, double t, const Eigen::Ref<const VectorX>& q,
                 const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& tau,
                 const Eigen::Ref<const VectorX>& friction_dq) noexcept;

  /// After an edit of the model's mass properties (a payload): recomputes the momentum of the
  /// last (q, q̇) with `model` (momentum_terms on `data`), so that the next Δy contains no jump
  /// and r stays continuous (the change is taken as made at t_k). Nothing to do before reset.
  /// Allocation-free.
  void reanchor(const Model& model, Data& data) noexcept;

  /// r ≈ τ̂_ext (n), after the last update (zero after reset).
  [[nodiscard]] const VectorX& residual() const noexcept { return r_; }
  [[nodiscard]] bool initialized() const noexcept { return initialized_; }
  [[nodiscard]] double time() const noexcept { return t_; }
  [[nodiscard]] const VectorX& gains() const noexcept { return gains_; }
  [[nodiscard]] const JointFriction& friction() const noexcept { return friction_; }
  /// Friction torques τ_f(q̇) of the last sample (n).
  [[nodiscard]] const VectorX& friction_torque() const noexcept { return tau_f_; }
  /// The Dahl sign's state z_i of the last sample (n; zero after reset, and unless the
  /// friction's sign is kDahl).
  [[nodiscard]] const VectorX& presliding_state() const noexcept { return presliding_state_; }
  [[nodiscard]] int nq() const noexcept { return n_; }

 private:
  /// The model has the observer's n joints and `data` its size (see reset).
  [[nodiscard]] bool sized_for(const Model& model, const Data& data) const noexcept;
  /// τ_f(q̇) and γ = Cᵀq̇ − g − τ_f from the momentum terms in `data`.
  void integrand(const Data& data, const Eigen::Ref<const VectorX>& dq) noexcept;
  /// m_prev_ = data.momentum + δI q̇: the momentum of a new anchor sample.
  void anchor_momentum(const Data& data, const Eigen::Ref<const VectorX>& dq) noexcept;

  int n_ = 0;
  VectorX gains_;
  JointFriction friction_;
  VectorX inertia_correction_;  ///< δI (n); zero by default

  // State.
  bool initialized_ = false;
  bool have_tau_ = false;  ///< tau_prev_ holds the torque of the current interval
  double t_ = 0.0;
  VectorX r_;                 ///< residual r_k
  VectorX presliding_state_;  ///< the Dahl sign's z_k (friction.hpp)
  VectorX m_prev_;            ///< m_k = B(q_k) q̇_k + δI q̇_k
  VectorX gamma_prev_;        ///< γ_k = Cᵀq̇ − g − τ_f at sample k
  VectorX tau_prev_;          ///< τ_k (held over [t_k, t_{k+1}))
  VectorX q_prev_, dq_prev_;
  VectorX friction_dq_prev_;  ///< the q̇ friction was evaluated at, sample k

  // Cached e^{−K Δt} for the last Δt (uniform sampling computes the exponentials once).
  double alpha_dt_ = -1.0;
  VectorX alpha_;

  // Scratch.
  VectorX tau_f_, gamma_;
};

}  // namespace extwrench
