// The uncertainty of every estimate (issue 9; docs/estimator.md#uncertainty): the noise levels of
// the residual (per joint) and of the base sensor (per axis of S) propagated to first order
// through the Table I solve actually used (wrench_cases.hpp, damped or not), plus a bound on the
// bias that damping adds, then to the moment at a known point, the line of action and its
// surface point. Everything is a 3×3 or 6×6 covariance; the scalar 1-σ reported is √trace Σ, the
// RMS norm of the error vector.
//
// Real time: noexcept, fixed-size storage (no allocation), O(n) per sample.
#pragma once

#include "extwrench/core/types.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/estimation/wrench_cases.hpp"

namespace extwrench {

/// Noise levels (1-σ) the uncertainty is propagated from; `calibration: CALIB.yaml` fills the
/// ones it measured (docs/config.md#uncertainty). Zero: that source is taken as noise-free.
struct UncertaintyOptions {
  VectorX residual_sigma = VectorX::Zero(1);      ///< of τ̂_ext per joint [N m], size 1 or n
  Vector3 sensor_force_sigma = Vector3::Zero();   ///< of the force reading per axis of S [N]
  Vector3 sensor_moment_sigma = Vector3::Zero();  ///< of the moment reading per axis of S [N m]
  /// `uncertain` when the force's `uncertain_sigmas`-σ error bound exceeds this fraction of the
  /// smallest force consistent with it (force_uncertain).
  double uncertain_fraction = 0.5;
  double uncertain_sigmas = 3.0;
};

/// The noise levels as variances, the sensor's rotated into W (constant: X_WS is fixed).
struct NoiseModel {
  VectorX residual_variance;           ///< σ² of τ̂_ext per joint (n) [N² m²]
  Matrix3 force_W = Matrix3::Zero();   ///< Σ of the sensor force in W [N²]
  Matrix3 moment_W = Matrix3::Zero();  ///< Σ of the sensor moment in W [N² m²]
  /// Some level is > 0. Without any (none configured, no calibration) the uncertainty is not
  /// estimated: σ stay NaN and `uncertain` is never set (a σ of 0 would claim exactness).
  bool configured = false;
};

/// The NoiseModel of the options for n joints and the sensor rotation R_WS (sizes validated).
[[nodiscard]] NoiseModel make_noise_model(const UncertaintyOptions& options, int n,
                                          const Matrix3& R_WS);

/// Σ of (F̂; M̄ about O_l) of a fit with fit.ok (wrench_case). In: the sensor type, J = J_l (6×n,
/// the Jacobian of O_l the fit used), l, the fit, the noise, r_{s,l} = O_l − p_s. Cases:
///   C  (F̂, M̄) = T (F̂, n_m − ñ_g), T = [I 0; −[r_{s,l}]× I]:   Σ = T diag(Σ_f, Σ_n) Tᵀ
///   D  M̄ = A⁻¹ J_ω (τ̂ − J_vᵀ F̂), A = J_ω J_ωᵀ + μ² I:          Σ_M̄ = A⁻¹ (J_ω Σ_τ J_ωᵀ
///      + C Σ_f Cᵀ) A⁻¹ + bias, Σ_M̄F = −A⁻¹ C Σ_f, C = J_ω J_vᵀ
///   E  W̄ = A⁻¹ J τ̂, A = J Jᵀ + μ² I:                          Σ = A⁻¹ J Σ_τ Jᵀ A⁻¹ + bias
/// bias = ‖x̂‖² μ⁴ A⁻², the second moment of the damping's bias −μ² A⁻¹ x with x taken as
/// ‖x̂‖ in every direction (x̂ the solved unknowns). NaN when A cannot be factored.
/// A partial fit (D, E: the minimum-norm solution on the observable subspace) takes for A⁻¹ the
/// pseudo-inverse P = Σ_k v_k v_kᵀ / λ_k over the kept eigenvectors v_k of J Jᵀ (fit.basis_W) and
/// has no damping bias: Σ is the observable part's, zero across the unobservable directions.
[[nodiscard]] Matrix6 wrench_covariance(SensorType type, const Matrix6X& J, int link,
                                        const WrenchFit& fit, const NoiseModel& noise,
                                        const Vector3& r_sl) noexcept;

/// Σ of the force of a known point without a sensor on a short chain (the partial fit of
/// J_v,pᵀ F = τ̂, fit.basis_W's top-left block): P J_v,p Σ_τ J_v,pᵀ P, P the pseudo-inverse of
/// J_v,p J_v,pᵀ on the observable subspace. In: J_p, the Jacobian of the point (6×n).
[[nodiscard]] Matrix3 known_point_force_covariance(const Matrix6X& J_p, int link,
                                                   const WrenchFit& fit,
                                                   const NoiseModel& noise) noexcept;

/// Whether the force alone at a known point explains the residual (the partial fit of
/// known_point_force_covariance): χ² = Σ_{i≤l} (τ̂_i − J_v,p,iᵀ F̂)² / σ_i² on l − rank degrees of
/// freedom. Returns χ²/(l − rank), the factor Σ_F grows by, when χ² exceeds
/// (l − rank) + 4 √(2 (l − rank)) (about 0.5 % of consistent samples); 1 otherwise, and when
/// l ≤ rank (nothing to refute it with).
[[nodiscard]] double point_force_misfit(const Matrix6X& J_p, int link, const VectorX& tau_ext,
                                        const WrenchFit& fit, const NoiseModel& noise) noexcept;

/// Σ of M = M̄ − r_{l,p} × F (the moment at a known point) from Σ of (F; M̄).
[[nodiscard]] Matrix3 moment_at_point_covariance(const Matrix6& wrench,
                                                 const Vector3& r_lp) noexcept;

/// Σ of the line of action's offset perpendicular to it at the point p̂ + λ u (19)–(21), to first
/// order in (F̂, M̄): p = O_l + F × M̄ / ‖F‖² + λ F / ‖F‖. In: F̂, M̄, their Σ, λ [m].
[[nodiscard]] Matrix3 line_covariance(const Vector3& force, const Vector3& moment_O,
                                      const Matrix6& wrench, double lambda) noexcept;

/// Σ of the line's entry point on a surface with outward normal n: a perpendicular shift δ of
/// the line moves the entry by (I − u nᵀ / nᵀu) δ.
[[nodiscard]] Matrix3 surface_point_covariance(const Matrix3& line, const Vector3& direction,
                                               const Vector3& normal) noexcept;

/// The scalar 1-σ reported: √trace Σ (RMS norm of the error; NaN for a NaN Σ).
[[nodiscard]] double rms_sigma(const Matrix3& covariance) noexcept;

/// `uncertain`: z σ_f > fraction (‖F̂‖ − z σ_f), z = uncertain_sigmas. A force not flagged is
/// then within `fraction` of the true one whenever its error is within z σ_f.
[[nodiscard]] bool force_uncertain(double sigma_force, double force_norm,
                                   const UncertaintyOptions& options) noexcept;

}  // namespace extwrench
