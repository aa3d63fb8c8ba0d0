// The cases of Table I on the isolated link l (docs/estimator.md), O_l the origin of body l's
// frame, J_l = [J_v,l; J_ω,l] the Jacobian of O_l (6×n, zero beyond l):
//   A  F̂ = f_m − f̃_g                                  (11)   force or F/T sensor (base_sensor.hpp)
//   B  M̂ = n_m − ñ_g − r_{s,p} × F̂                    (15)   F/T, known point
//   C  M̃ = n_m − r_{s,l} × F̂ − ñ_g,  r̂ = F̂ × M̃/‖F̂‖²  (16–20) F/T, pure force
//   D  M̄̂ = (J_ω,lᵀ)# (τ̂_1:l − J_v,lᵀ F̂)               (26)   force sensor, rank J_ω,l = 3
//   E  W̄ = (J_lᵀ)# τ̂_1:l                              (27)   no sensor, rank J_l = 6
// The wrench is carried as (F̂, M̄), M̄ the moment about O_l (M̄ = M_ext + r_{l,p} × F_ext).
// Real time: inline, noexcept, no allocation.
#pragma once

#include <cmath>
#include <limits>

#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/estimation/damped_least_squares.hpp"

namespace extwrench {

/// The wrench of one Table I case. A quantity that was not estimated is NaN.
struct WrenchFit {
  Vector3 force_W = Vector3::Constant(std::numeric_limits<double>::quiet_NaN());  ///< F̂
  Vector3 moment_O = Vector3::Constant(std::numeric_limits<double>::quiet_NaN());  ///< M̄, about O_l
  bool ok = false;            ///< (F̂, M̄) estimated
  bool damped = false;        ///< damped least squares active (cases D, E; partial too)
  bool fitted_force = false;  ///< F̂ comes from the fit (case E), not the sensor
  double condition = std::numeric_limits<double>::quiet_NaN();  ///< κ of the inverted Jacobian
  double damping = 0.0;  ///< μ² of the damped solve (cases D, E; partial too); 0 when undamped
  /// Rank test failed (cases D, E): force_W / moment_O hold the minimum-norm solution on the
  /// observable subspace (ok stays false: no line of action), basis_W its orthonormal basis in
  /// (F; M̄) coordinates, first `rank` columns.
  bool partial = false;
  /// partial: the force alone at a known point (no sensor, J_v,pᵀ F = τ̂), basis_W's top-left.
  bool point_force = false;
  int rank = 0;
  /// Meaningful only when `partial` (fit_wrench_case leaves it as it was otherwise).
  Eigen::Matrix<double, 6, 6> basis_W = Eigen::Matrix<double, 6, 6>::Zero();
};

/// Case D's observable part: the sensor's force (all of F) and the observable moment directions.
template <typename Jacobian>
inline void partial_moment(const Jacobian& J, int link, const VectorX& b,
                           const SolverOptions& solver, WrenchFit& fit) noexcept {
  Vector3 x;
  Matrix3 basis;
  const int r =
      min_norm_solve<3>(J.template bottomRows<3>(), link, b, solver, x, basis, fit.damping);
  fit.moment_O = x;
  fit.damped = fit.damping > 0.0;
  fit.partial = true;
  fit.basis_W.setZero();
  fit.basis_W.template topLeftCorner<3, 3>().setIdentity();
  fit.basis_W.template block<3, 3>(3, 3) = basis;
  fit.rank = 3 + r;
}

/// Case E's observable part: the minimum-norm wrench (F̂; M̄) on the observable subspace.
template <typename Jacobian>
inline void partial_wrench(const Jacobian& J, int link, const VectorX& tau_ext,
                           const SolverOptions& solver, WrenchFit& fit) noexcept {
  Vector6 x;
  Eigen::Matrix<double, 6, 6> basis;
  fit.rank = min_norm_solve<6>(J, link, tau_ext, solver, x, basis, fit.damping);
  fit.damped = fit.damping > 0.0;
  fit.force_W = x.head<3>();
  fit.moment_O = x.tail<3>();
  fit.basis_W = basis;
  fit.partial = true;
}

/// Table I case stage. In: the sensor type, J = J_l (6×n), l, τ̂_ext (n), the base wrench
/// (F̂, n_m − ñ_g of base_wrench; unused for kNone), O_l, the sensor origin p_WS, the solver
/// options. Scratch: b (n), the spectrum guess of the damped solves. Out: `fit`, every field set
/// (basis_W only when partial: a fit reused in the loop costs no 6×6 copy or zeroing); when the
/// rank test fails and observable_part, its observable part (partial_moment, partial_wrench).
template <typename Jacobian>
inline void fit_wrench_case(WrenchFit& fit, SensorType type, const Jacobian& J, int link,
                            const VectorX& tau_ext, const BaseWrench& base, const Vector3& O_l,
                            const Vector3& p_WS, const SolverOptions& solver, VectorX& b,
                            SpectrumGuess& guess, bool observable_part = true) noexcept {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  fit.force_W.setConstant(kNaN);
  fit.moment_O.setConstant(kNaN);
  fit.ok = false;
  fit.damped = false;
  fit.fitted_force = false;
  fit.condition = kNaN;
  fit.damping = 0.0;
  fit.partial = false;
  fit.point_force = false;
  fit.rank = 0;
  if (type == SensorType::kForceTorque) {
    // C (17): M̃ = n_m − ñ_g − r_{s,l} × F̂, the moment about O_l.
    fit.force_W = base.force_W;
    fit.moment_O = base.dn_W - (O_l - p_WS).cross(base.force_W);
    fit.ok = true;
  } else if (type == SensorType::kForce) {
    // D (26): M̄̂ = (J_ω,lᵀ)# (τ̂_1:l − J_v,lᵀ F̂), rank J_ω,l = 3 required.
    fit.force_W = base.force_W;
    b = tau_ext;
    b.noalias() -= J.template topRows<3>().transpose() * base.force_W;
    Vector3 x;
    const DlsInfo info = damped_solve<3>(J.template bottomRows<3>(), link, b, solver, x, guess);
    fit.condition = info.condition;
    if (info.rank_ok) {
      fit.moment_O = x;
      fit.ok = true;
      fit.damped = info.damped;
      fit.damping = info.damping;
    } else if (observable_part && link > 0 && base.force_W.allFinite()) {
      partial_moment(J, link, b, solver, fit);
    }
  } else {
    // E (27): W̄ = (J_lᵀ)# τ̂_1:l, rank J_l = 6 required.
    Vector6 x;
    const DlsInfo info = damped_solve<6>(J, link, tau_ext, solver, x, guess);
    fit.condition = info.condition;
    if (info.rank_ok) {
      fit.force_W = x.head<3>();
      fit.moment_O = x.tail<3>();
      fit.ok = true;
      fit.damped = info.damped;
      fit.damping = info.damping;
      fit.fitted_force = true;
    } else if (observable_part && link > 0) {
      partial_wrench(J, link, tau_ext, solver, fit);
      fit.fitted_force = fit.rank > 0;
    }
  }
}

/// The same, returned by value.
template <typename Jacobian>
[[nodiscard]] inline WrenchFit wrench_case(SensorType type, const Jacobian& J, int link,
                                           const VectorX& tau_ext, const BaseWrench& base,
                                           const Vector3& O_l, const Vector3& p_WS,
                                           const SolverOptions& solver, VectorX& b,
                                           SpectrumGuess& guess,
                                           bool observable_part = true) noexcept {
  WrenchFit fit;
  fit_wrench_case(fit, type, J, link, tau_ext, base, O_l, p_WS, solver, b, guess, observable_part);
  return fit;
}

/// Known point (15). In: the fit (ok), the point p_W, O_l. Out: M̂_ext = M̄ − r_{l,p} × F̂
/// (= n_m − ñ_g − r_{s,p} × F̂ with the F/T sensor).
[[nodiscard]] inline Vector3 known_point_moment(const WrenchFit& fit, const Vector3& p_W,
                                                const Vector3& O_l) noexcept {
  return fit.moment_O - (p_W - O_l).cross(fit.force_W);
}

/// Line of action (19)–(21). In: the fit (ok), O_l. Out: p̂ = O_l + F̂ × M̄ / ‖F̂‖², the point of
/// the line nearest O_l, and the unit direction F̂/‖F̂‖; false when ‖F̂‖ is 0 or not finite.
[[nodiscard]] inline bool line_of_action(const WrenchFit& fit, const Vector3& O_l,
                                         Vector3& line_point_W, Vector3& direction_W) noexcept {
  const Vector3& F = fit.force_W;
  const double f2 = F.squaredNorm();
  if (!(f2 > 0.0 && std::isfinite(f2))) return false;
  line_point_W = O_l + F.cross(fit.moment_O) / f2;
  direction_W = F / std::sqrt(f2);
  return true;
}

/// The share of the largest torque the estimated wrench can put on a joint, ‖J_v,i‖‖F̂‖ +
/// ‖J_ω,i‖‖M̄‖, by which a single contact's prediction may miss τ̂_ext,i beyond τ_min,i: the
/// wrench carries the model's and the sensor's errors (a few per cent of F̂ in MuJoCo's
/// collisions), and calibrated thresholds are far below them. 5 %: a second contact of 10 N
/// beside 15 N is still flagged on every sample (EstimatorLoop tests).
inline constexpr double kConsistencyShare = 0.05;

/// Consistency: a single wrench on link l must reproduce τ̂_ext = J_lᵀ (F̂, M̄) on every joint
/// within τ_min,i + kConsistencyShare (‖J_v,i‖‖F̂‖ + ‖J_ω,i‖‖M̄‖). In: J = J_l, the fit, τ̂_ext,
/// τ_min (n). Scratch: tau_pred (n). True when some joint differs by more (two contacts, or a
/// contact on another link).
template <typename Jacobian>
[[nodiscard]] inline bool contradicts_residual(const Jacobian& J, const WrenchFit& fit,
                                               const VectorX& tau_ext, const VectorX& tau_min,
                                               VectorX& tau_pred) noexcept {
  Vector6 w;
  w << fit.force_W, fit.moment_O;
  tau_pred.noalias() = J.transpose() * w;
  const double force = fit.force_W.norm(), moment = fit.moment_O.norm();
  bool inconsistent = false;
  for (Eigen::Index i = 0; i < tau_pred.size(); ++i) {
    const double miss = std::abs(tau_pred[i] - tau_ext[i]);
    if (!(miss > tau_min[i])) continue;  // within τ_min: no norm needed (the common case)
    const double reach =
        J.col(i).template head<3>().norm() * force + J.col(i).template tail<3>().norm() * moment;
    if (miss > tau_min[i] + kConsistencyShare * reach) inconsistent = true;
  }
  return inconsistent;
}

}  // namespace extwrench
