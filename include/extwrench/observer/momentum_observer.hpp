// The momentum residual (SPEC §2, eq. 4): a virtual sensor of the external joint torques.
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
#pragma once

#include <memory>

#include "extwrench/core/status.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/observer/friction.hpp"

namespace extwrench {

class MomentumObserver {
 public:
  /// Keeps its own copy of `model` (payload changes edit that copy, never the caller's) and
  /// sizes every buffer once. `gains`: K_i > 0 [1/s], size n, or size 1 for the same K on every
  /// joint. Friction defaults to the model's Joint::damping / Joint::friction.
  /// Throws extwrench::Error on a bad gain or an empty model.
  MomentumObserver(Model model, const VectorX& gains);
  MomentumObserver(Model model, double gain);

  /// Sets K (size n or 1, every entry > 0 and finite). Throws extwrench::Error otherwise.
  /// Allocation-free; the residual keeps its value.
  void set_gains(const VectorX& gains);
  void set_friction(const JointFriction& friction);  ///< throws extwrench::Error on bad sizes

  /// Adds a payload (mass properties in the frame of `body`) to body `body`, replacing any
  /// previous payload on any body. The integral state is shifted by the momentum jump at the
  /// last (q, q̇) so that r is continuous. Allocation-free. kWrongSize for a bad body index,
  /// kNonFinite for a NaN/Inf entry or a negative mass (then nothing changes).
  [[nodiscard]] Status set_payload(int body, const Inertia& payload) noexcept;
  /// Removes the payload (same continuity as set_payload).
  void clear_payload() noexcept;

  /// Starts (or restarts) the observer at time t: r = 0, m(0) = B(q) q̇. The torque of the
  /// interval [t, t_1) is `tau`; the overload without it takes the first update's torque.
  [[nodiscard]] Status reset(double t, const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq) noexcept;
  [[nodiscard]] Status reset(double t, const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq,
                             const Eigen::Ref<const VectorX>& tau) noexcept;

  /// One sample: t > previous t, q, q̇, τ (commanded joint torques) of size n, all finite.
  /// On an input error the Status names the channel and index and nothing is changed
  /// (the state stays bit-identical). O(n), no allocation.
  [[nodiscard]] Status update(double t, const Eigen::Ref<const VectorX>& q,
                              const Eigen::Ref<const VectorX>& dq,
                              const Eigen::Ref<const VectorX>& tau) noexcept;

  /// Checks (t, q, q̇, τ) as update() would, without changing anything.
  [[nodiscard]] Status validate(double t, const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau) const noexcept;

  /// r ≈ τ̂_ext (n), after the last update (zero after reset).
  [[nodiscard]] const VectorX& residual() const noexcept { return r_; }
  [[nodiscard]] bool initialized() const noexcept { return initialized_; }
  [[nodiscard]] double time() const noexcept { return t_; }
  [[nodiscard]] const VectorX& gains() const noexcept { return gains_; }
  /// The model in use (payload included).
  [[nodiscard]] const Model& model() const noexcept { return model_; }
  [[nodiscard]] const JointFriction& friction() const noexcept { return friction_; }
  /// Friction torques τ_f(q̇) of the last sample (n).
  [[nodiscard]] const VectorX& friction_torque() const noexcept { return tau_f_; }
  [[nodiscard]] int nq() const noexcept { return n_; }

  /// The dynamics workspace. After update()/reset() its poses and motion subspaces (X_WB, S)
  /// are those of the last q, and momentum / coriolis_transpose_dq / gravity_torque those of
  /// the last (q, q̇). The world-frame mass properties are not computed (the residual does not
  /// need them): call world_mass_properties(model(), workspace()) before a *_no_kinematics
  /// algorithm that reads them. Every other buffer is scratch that a caller (the
  /// ContactEstimator) may overwrite between updates.
  [[nodiscard]] Data& workspace() noexcept { return data_; }
  [[nodiscard]] const Data& workspace() const noexcept { return data_; }

 private:
  friend class ContactEstimator;  // validates the sample itself, then calls advance()

  /// What advance() leaves in the workspace besides the momentum terms and the poses.
  enum class Extras { kNone, kWorldInertias, kWorldInertiasAndBias };
  /// update() without the input checks: the caller has validated (t, q, q̇, τ).
  void advance(double t, const Eigen::Ref<const VectorX>& q, const Eigen::Ref<const VectorX>& dq,
               const Eigen::Ref<const VectorX>& tau,
               Extras extras = Extras::kNone) noexcept;
  void compute_terms(const Eigen::Ref<const VectorX>& q, const Eigen::Ref<const VectorX>& dq,
                     Extras extras = Extras::kNone) noexcept;
  void apply_payload(int body, const Inertia* payload) noexcept;

  Model model_;
  std::vector<Inertia> nominal_inertia_;  ///< bodies' inertia without payload
  int payload_body_ = -1;
  Data data_;
  int n_ = 0;
  VectorX gains_;
  JointFriction friction_;

  // State.
  bool initialized_ = false;
  bool have_tau_ = false;  ///< tau_prev_ holds the torque of the current interval
  double t_ = 0.0;
  VectorX r_;           ///< residual r_k
  VectorX m_prev_;      ///< m_k = B(q_k) q̇_k
  VectorX gamma_prev_;  ///< γ_k = Cᵀq̇ − g − τ_f at sample k
  VectorX tau_prev_;    ///< τ_k (held over [t_k, t_{k+1}))
  VectorX q_prev_, dq_prev_;

  // Cached e^{−K Δt} for the last Δt (uniform sampling computes the exponentials once).
  double alpha_dt_ = -1.0;
  VectorX alpha_;

  // Scratch.
  VectorX tau_f_, gamma_;
};

}  // namespace extwrench
